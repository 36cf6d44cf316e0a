// Exact validation of a Mesh<Dim>: topology by sorted facet keys (integer node ids), geometry
// (hanging and duplicate nodes) by a uniform grid over the used nodes with element-relative tolerances.

#include "core/validate.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "core/fnv_lanes.hpp"
#include "core/incidence_csr.hpp"
#include "core/mesh_topology.hpp"
#include "core/parallel_ranges.hpp"
#include "core/point_grid.hpp"
#include "core/quality.hpp"
#include "core/sort_short.hpp"

namespace febemesh {

namespace {

/// Implicit k-d tree over a subset of the points (ids), leaves of at most 8 points.
template <int Dim> class PointTree {
 public:
  PointTree(const std::vector<Point<Dim>>& pts, std::vector<std::int32_t> ids) : pts_(pts), ids_(std::move(ids)) {
    build(0, ids_.size(), 0);
  }

  /// Calls visit(id) for every point inside the closed box.
  template <class Visit> void query(const Box<Dim>& box, Visit&& visit) const {
    query(0, ids_.size(), 0, box, visit);
  }

 private:
  static constexpr std::size_t leaf_size = 8;

  void build(std::size_t lo, std::size_t hi, int depth) {
    if (hi - lo <= leaf_size) return;
    const std::size_t mid = lo + (hi - lo) / 2;
    const int axis = depth % Dim;
    std::nth_element(ids_.begin() + static_cast<std::ptrdiff_t>(lo), ids_.begin() + static_cast<std::ptrdiff_t>(mid),
                     ids_.begin() + static_cast<std::ptrdiff_t>(hi), [&](std::int32_t a, std::int32_t b) {
                       const double ca = pts_[a][axis], cb = pts_[b][axis];
                       return ca != cb ? ca < cb : a < b;
                     });
    build(lo, mid, depth + 1);
    build(mid + 1, hi, depth + 1);
  }

  template <class Visit> void query(std::size_t lo, std::size_t hi, int depth, const Box<Dim>& box, Visit& visit) const {
    if (hi - lo <= leaf_size) {
      for (std::size_t i = lo; i < hi; ++i)
        if (box.contains(pts_[ids_[i]])) visit(ids_[i]);
      return;
    }
    const std::size_t mid = lo + (hi - lo) / 2;
    const int axis = depth % Dim;
    const double split = pts_[ids_[mid]][axis];
    if (box.contains(pts_[ids_[mid]])) visit(ids_[mid]);
    if (box.lo[axis] <= split) query(lo, mid, depth + 1, box, visit);
    if (box.hi[axis] >= split) query(mid + 1, hi, depth + 1, box, visit);
  }

  const std::vector<Point<Dim>>& pts_;
  std::vector<std::int32_t> ids_;
};

class Problems {
 public:
  Problems(ValidationReport& r, int max) : r_(r), max_(max) {}
  /// One problem: what it is (ProblemSite::kind), the node it is at (-1: none) and its text.
  template <class Write> void add(const char* kind, std::int32_t node, Write&& write) {
    ++r_.n_problems;
    if (static_cast<int>(r_.problems.size()) >= max_) return;
    std::ostringstream os;
    os.precision(17);
    write(os);
    r_.problems.push_back(os.str());
    r_.sites.push_back({kind, node});
  }

 private:
  ValidationReport& r_;
  int max_;
};

template <int Dim> std::string fmt(const Point<Dim>& p) {
  std::ostringstream os;
  os.precision(17);
  os << "(" << p[0];
  for (int d = 1; d < Dim; ++d) os << ", " << p[d];
  os << ")";
  return os.str();
}

template <int Dim> std::string fmt_element(const Elements& els, std::size_t e, const std::vector<Point<Dim>>& pts) {
  std::ostringstream os;
  os << name(els.type[e]) << " " << e << " [";
  const VertexId* n = els.nodes(ElemId{static_cast<std::int32_t>(e)});
  for (int i = 0; i < els.n_nodes_of(ElemId{static_cast<std::int32_t>(e)}); ++i) {
    os << (i ? " " : "") << n[i].v;
    if (n[i].v >= 0 && static_cast<std::size_t>(n[i].v) < pts.size()) os << fmt<Dim>(pts[n[i].v]);
  }
  os << "]";
  return os.str();
}

std::string fmt_key(const FacetKey& k) {
  std::ostringstream os;
  os << "{";
  for (int i = 0; i < 4 && k.v[i] >= 0; ++i) os << (i ? " " : "") << k.v[i];
  os << "}";
  return os.str();
}

/// Elements with the right dimension, node count and node ids in range.
template <int Dim> void check_elements(const Elements& els, int dim, const char* group, std::size_t n_points,
                                       ValidationReport& r, Problems& problems) {
  if (els.offset.size() != els.size() + 1 || els.offset.back() != static_cast<std::int32_t>(els.node.size())) {
    ++r.bad_elements;
    problems.add("bad element", -1, [&](auto& os) { os << group << ": offset array inconsistent with the node array"; });
    return;
  }
  for (std::size_t e = 0; e < els.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    bool ok = dimension(els.type[e]) == dim && els.n_nodes_of(id) == n_nodes(els.type[e]);
    for (int i = 0; ok && i < els.n_nodes_of(id); ++i)
      ok = els.nodes(id)[i].v >= 0 && static_cast<std::size_t>(els.nodes(id)[i].v) < n_points;
    if (!ok) {
      ++r.bad_elements;
      problems.add("bad element", -1, [&](auto& os) {
        os << group << " element " << e << " (" << name(els.type[e]) << "): wrong dimension, node count or node id";
      });
    }
  }
}

/// Is p within tol of the open segment (a, b), away from its ends by more than tol?
template <int Dim> bool on_open_segment(const Point<Dim>& p, const Point<Dim>& a, const Point<Dim>& b, double rel) {
  const Point<Dim> ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 == 0.0) return false;
  const double t = (p - a).dot(ab) / len2;
  if (t <= rel || t >= 1.0 - rel) return false;
  return (p - a - t * ab).squaredNorm() <= rel * rel * len2;
}

/// Barycentric coordinates of p's projection on triangle (a, b, c) and its distance to the plane.
std::pair<Eigen::Vector3d, double> barycentric(const Point<3>& p, const Point<3>& a, const Point<3>& b, const Point<3>& c) {
  const Point<3> n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 == 0.0) return {Eigen::Vector3d::Constant(-1.0), 0.0};
  const double l0 = (b - p).cross(c - p).dot(n) / n2;
  const double l1 = (c - p).cross(a - p).dot(n) / n2;
  return {Eigen::Vector3d(l0, l1, 1.0 - l0 - l1), std::abs((p - a).dot(n)) / std::sqrt(n2)};
}

/// The size of a facet: its longest edge.
double facet_size(const Facet& f, const std::vector<Point<3>>& pts) {
  double h = 0.0;
  for (int i = 0; i < f.n; ++i) h = std::max(h, (pts[f.node[(i + 1) % f.n].v] - pts[f.node[i].v]).norm());
  return h;
}

/// Is a point on the interior of a triangle facet (within rel * h of its plane, h its size,
/// strictly inside its edges)? The normal once, and for each point the distance to the plane
/// first (most points tested are off the plane, and then no barycentric coordinates are
/// needed); the same numbers as barycentric() (the facet check was a third of the 3D
/// validation: sphere966 level 6, 0.35 s of 1.1).
class TriangleInterior {
 public:
  TriangleInterior(const Point<3>& a, const Point<3>& b, const Point<3>& c, double h, double rel)
      : a_(a), b_(b), c_(c), n_((b - a).cross(c - a)), n2_(n_.squaredNorm()), root_(std::sqrt(n2_)), tol_(rel * h), rel_(rel),
        none_(h == 0.0 || n2_ == 0.0) {}
  bool contains(const Point<3>& p) const {
    if (none_) return false;
    if (!(std::abs((p - a_).dot(n_)) / root_ <= tol_)) return false;
    const double l0 = (b_ - p).cross(c_ - p).dot(n_) / n2_;
    const double l1 = (c_ - p).cross(a_ - p).dot(n_) / n2_;
    return Eigen::Vector3d(l0, l1, 1.0 - l0 - l1).minCoeff() > rel_;
  }

 private:
  Point<3> a_, b_, c_, n_;
  double n2_, root_, tol_, rel_;
  bool none_;  ///< a degenerate triangle (or facet size 0): no interior
};

/// Is p on the interior of the quad facet f (within rel * size of its plane, strictly inside
/// its edges)? h is facet_size(f, pts), computed once per facet by the caller. Triangle facets:
/// TriangleInterior.
bool on_quad_interior(const Point<3>& p, const Facet& f, double h, const std::vector<Point<3>>& pts, double rel) {
  if (h == 0.0) return false;
  // As triangles (0,1,2) and (0,2,3): the diagonal 0-2 belongs to the interior.
  const auto& a = pts[f.node[0].v];
  const auto& c = pts[f.node[2].v];
  const auto [l1, d1] = barycentric(p, a, pts[f.node[1].v], c);
  if (d1 <= rel * h && l1[0] > rel && l1[2] > rel && l1[1] >= -rel) return true;
  const auto [l2, d2] = barycentric(p, a, c, pts[f.node[3].v]);
  return d2 <= rel * h && l2[0] > rel && l2[2] > rel && l2[1] >= -rel;
}

template <int Dim> Box<Dim> inflated_box(std::initializer_list<Point<Dim>> corners, double margin) {
  Box<Dim> b = Box<Dim>::empty();
  for (const auto& c : corners) b.expand(c);
  b.lo.array() -= margin;
  b.hi.array() += margin;
  return b;
}


/// facet_uses(solid) grouped by key: the groups in key order, each group's uses in (element,
/// local facet) order, the same as facet_uses gives them. A solid of tetrahedra, or of triangles
/// and quads (whose facets are their edges (k, k+1)), is held at 4 bytes a use: the uses bucketed
/// by the key's smallest node, each an element and local facet (element << 2 | facet), ordered
/// within the bucket by the rest of the key, which is made again from the element when needed.
/// facet_uses' 24 bytes a use (96 a tetrahedron) were the CLI's memory peak in the validation
/// (sphere966 level 6), and the keys stored beside the uses (12 bytes a use) were still its peak
/// in session 35 (72 MB of 163 MB at 1.5 M tetrahedra). For triangles facet_uses' sort was 0.24
/// s of the 2D validation's 0.44 (flange at 968,326 triangles, one thread; 70 MB).
/// `bucketed` false: facet_uses for every solid (the slow twin, ValidateOptions::bucketed_facets).
class FacetGroups {
 public:
  FacetGroups(const Elements& els, int n_threads, bool bucketed = true) : els_(els) {
    const bool small = els.size() < (std::size_t(1) << 29);
    tets_ = small && std::all_of(els.type.begin(), els.type.end(), [](ElemType t) { return t == ElemType::Tet4; });
    polygons_ = small && !els.empty() && std::all_of(els.type.begin(), els.type.end(), [](ElemType t) {
                  return t == ElemType::Tri3 || t == ElemType::Quad4;
                });
    if (!bucketed) tets_ = polygons_ = false;
    if (!tets_ && !polygons_) {
      uses_ = facet_uses(els);
      for (std::size_t i = 0; i < uses_.size(); ++i) n_groups_ += i == 0 || uses_[i].key != uses_[i - 1].key;
      return;
    }
    std::int32_t top = -1;  // node ids are in range (validate checked the elements)
    for (const VertexId v : els.node) top = std::max(top, v.v);
    const std::size_t n_buckets = static_cast<std::size_t>(top) + 1;
    start_.assign(n_buckets + 1, 0);
    // The uses bucketed by a counting sort over ranges of the elements, one a thread, each
    // counting into its own array (the first into start_): a bucket holds the first range's
    // uses, then the second's, ..., so its uses are in (element, local facet) order for every
    // thread count. (Serial, the two passes and the loop in for_each were about 0.1 s of the
    // two-thread validation's 0.40 s by perf samples, sphere966 at 995,232 tetrahedra; with
    // both on the threads it takes 0.35-0.39 s, and 0.58-0.61 s on one thread against 0.60-0.63.)
    const std::size_t n_ranges = els.size() < (std::size_t(1) << 16) ? 1 : static_cast<std::size_t>(std::clamp(n_threads, 1, 256));
    const auto range_of = [&](std::size_t w) { return std::pair{els.size() * w / n_ranges, els.size() * (w + 1) / n_ranges}; };
    const auto each_use = [&](std::size_t begin, std::size_t end, auto&& visit) {
      for (std::size_t e = begin; e < end; ++e) {
        const auto n = static_cast<std::uint32_t>(tets_ ? 4 : els.offset[e + 1] - els.offset[e]);
        for (std::uint32_t f = 0; f < n; ++f) {
          const std::uint32_t id = static_cast<std::uint32_t>(e << 2) | f;
          visit(key_of_use(id)[0], id);
        }
      }
    };
    // count[w][b]: range w's uses in bucket b (range 0's in start_[b + 1]), then where range w
    // writes its next use of bucket b.
    std::vector<std::vector<std::uint32_t>> count(n_ranges);
    for_each_chunk(n_ranges, 1, static_cast<int>(n_ranges), [&](std::size_t w, std::size_t, std::size_t) {
      std::uint32_t* c = start_.data() + 1;
      if (w > 0) count[w].assign(n_buckets, 0), c = count[w].data();
      const auto [begin, end] = range_of(w);
      each_use(begin, end, [&](std::int32_t a, std::uint32_t) { ++c[a]; });
    });
    std::vector<std::uint32_t> fill(n_buckets);
    for (std::size_t b = 0; b < n_buckets; ++b) {
      std::uint32_t at = start_[b];
      fill[b] = at, at += start_[b + 1];
      for (std::size_t w = 1; w < n_ranges; ++w) {
        const std::uint32_t k = count[w][b];
        count[w][b] = at, at += k;
      }
      start_[b + 1] = at;
    }
    ids_.resize(start_.back());
    for_each_chunk(n_ranges, 1, static_cast<int>(n_ranges), [&](std::size_t w, std::size_t, std::size_t) {
      std::uint32_t* at = w == 0 ? fill.data() : count[w].data();
      const auto [begin, end] = range_of(w);
      each_use(begin, end, [&](std::int32_t a, std::uint32_t id) { ids_[at[a]++] = id; });
    });
    count.clear();
    std::vector<std::uint32_t>().swap(fill);
    // Generation order is (element, local facet): a stable sort by the rest of the key. Each
    // bucket on its own (its range of ids_), so in chunks of buckets on n_threads; each chunk
    // counts its groups (chunk_groups_, for for_each's chunks).
    const std::size_t n_chunks = (n_buckets + chunk_buckets - 1) / chunk_buckets;
    chunk_groups_.assign(n_chunks + 1, 0);
    for_each_chunk_balanced(n_buckets, chunk_buckets, n_threads, [&](auto&& next) {
      std::vector<Keyed> bucket;
      for (std::size_t begin = 0, end = 0; next(begin, end);) {
        std::size_t groups = 0;
        for (std::size_t b = begin; b < end; ++b) {
          keyed_bucket(b, bucket);
          stable_sort_short(bucket.begin(), bucket.end(),
                            [](const Keyed& x, const Keyed& y) { return x.k1 != y.k1 ? x.k1 < y.k1 : x.k2 < y.k2; });
          for (std::size_t i = 0; i < bucket.size(); ++i) {
            ids_[start_[b] + i] = bucket[i].id;
            groups += i == 0 || !same_key(bucket[i - 1], bucket[i]);
          }
        }
        chunk_groups_[begin / chunk_buckets + 1] = groups;
      }
    });
    for (std::size_t c = 0; c < n_chunks; ++c) chunk_groups_[c + 1] += chunk_groups_[c];
    n_groups_ = chunk_groups_.back();
  }

  std::size_t n_groups() const { return n_groups_; }
  /// Whether the solid is triangles and quads, bucketed: then the distinct keys, in order, are
  /// the solid's distinct edges as unique_edges gives them.
  bool polygons() const { return polygons_; }

  /// The groups come in chunks of consecutive keys (for_each's c): bucketed, chunk c holds the
  /// buckets [c, c + 1) * chunk_buckets; otherwise there is one chunk.
  std::size_t n_chunks() const { return chunk_groups_.empty() ? 1 : chunk_groups_.size() - 1; }

  /// Calls group(c, i, std::span<const FacetUse>) for every distinct key, i its index in key
  /// order and c its chunk: the chunks on n_threads threads, each chunk's groups in key order on
  /// one thread (see the constructor for what it saves).
  template <class Group> void for_each(int n_threads, Group&& group) const {
    if (!tets_ && !polygons_) {
      std::size_t k = 0;
      for (std::size_t i = 0; i < uses_.size(); ++k) {
        std::size_t j = i + 1;
        while (j < uses_.size() && uses_[j].key == uses_[i].key) ++j;
        group(std::size_t{0}, k, std::span<const FacetUse>(uses_.data() + i, j - i));
        i = j;
      }
      return;
    }
    const std::size_t n_buckets = start_.size() - 1;
    for_each_chunk_balanced(n_chunks(), 1, n_threads, [&](auto&& next) {
      std::vector<FacetUse> g;
      std::vector<Keyed> bucket;
      for (std::size_t c = 0, c_end = 0; next(c, c_end);) {
        std::size_t k = chunk_groups_[c];
        for (std::size_t b = c * chunk_buckets; b < std::min(n_buckets, (c + 1) * chunk_buckets); ++b) {
          keyed_bucket(b, bucket);
          for (std::size_t i = 0; i < bucket.size(); ++k) {
            std::size_t j = i + 1;
            while (j < bucket.size() && same_key(bucket[j], bucket[i])) ++j;
            g.clear();
            for (std::size_t u = i; u < j; ++u) {
              const ElemId e{static_cast<std::int32_t>(bucket[u].id >> 2)};
              const int local = static_cast<int>(bucket[u].id & 3u);
              FacetUse use{FacetKey{}, e, static_cast<std::int8_t>(local),
                           static_cast<std::int8_t>(orientation_of(facet_of(els_, e, local)))};
              use.key.v = {static_cast<std::int32_t>(b), bucket[u].k1, bucket[u].k2, -1};
              g.push_back(use);
            }
            group(c, k, std::span<const FacetUse>(g));
            i = j;
          }
        }
      }
    });
  }

 private:
  struct Keyed {
    std::int32_t k1, k2;  ///< the key's second and third node
    std::uint32_t id;     ///< element << 2 | local facet
  };
  static bool same_key(const Keyed& x, const Keyed& y) { return x.k1 == y.k1 && x.k2 == y.k2; }

  /// The sorted key (a <= b <= c) of use id: facet f of a tetrahedron (Gmsh's table) is the
  /// triple without node 3 - f; of a triangle or quad, its nodes f and f + 1 (a <= b, c = -1).
  std::array<std::int32_t, 3> key_of_use(std::uint32_t id) const {
    const VertexId* v = els_.nodes(ElemId{static_cast<std::int32_t>(id >> 2)});
    if (polygons_) {
      const auto e = static_cast<std::size_t>(id >> 2);
      const auto f = static_cast<std::int32_t>(id & 3u);
      const std::int32_t a = v[f].v, b = v[f + 1 == els_.offset[e + 1] - els_.offset[e] ? 0 : f + 1].v;
      return {std::min(a, b), std::max(a, b), -1};
    }
    const int skip = 3 - static_cast<int>(id & 3u);
    std::array<std::int32_t, 3> t{};
    int m = 0;
    for (int i = 0; i < 4; ++i)
      if (i != skip) t[m++] = v[i].v;
    if (t[0] > t[1]) std::swap(t[0], t[1]);
    if (t[1] > t[2]) std::swap(t[1], t[2]);
    if (t[0] > t[1]) std::swap(t[0], t[1]);
    return t;
  }

  /// Bucket b's uses with the rest of their keys, in the order held.
  void keyed_bucket(std::size_t b, std::vector<Keyed>& out) const {
    out.clear();
    for (std::uint32_t i = start_[b]; i < start_[b + 1]; ++i) {
      const std::array<std::int32_t, 3> k = key_of_use(ids_[i]);
      out.push_back({k[1], k[2], ids_[i]});
    }
  }

  static constexpr std::size_t chunk_buckets = std::size_t(1) << 12;

  const Elements& els_;
  bool tets_ = false, polygons_ = false;
  std::size_t n_groups_ = 0;
  std::vector<std::size_t> chunk_groups_;  ///< bucketed: groups before chunk c (chunk_buckets buckets each); n_chunks + 1
  std::vector<FacetUse> uses_;         ///< other element types: facet_uses
  std::vector<std::uint32_t> start_;   ///< bucketed: bucket b (smallest node b) is ids_[start_[b], start_[b + 1])
  std::vector<std::uint32_t> ids_;     ///< element << 2 | local facet, by (key, element, local facet)
};
}  // namespace

std::string ValidationReport::summary() const {
  std::ostringstream os;
  os << (valid ? "valid" : "INVALID") << " mesh: " << n_points << " points, " << n_solid << " solid, "
     << n_interface << " interface elements; Euler characteristic " << euler;
  if (expected_euler) os << " (expected " << *expected_euler << ")";
  os << "\n";
  auto line = [&](const char* what, std::size_t n) {
    if (n != 0) os << "  " << what << ": " << n << "\n";
  };
  line("bad elements", bad_elements);
  line("inverted elements", inverted);
  line("non-conforming facets", nonconforming_facets);
  line("hanging nodes", hanging_nodes);
  line("interface: missing boundary facets", interface_missing);
  line("interface: extra elements", interface_extra);
  line("interface: reversed elements", interface_reversed);
  line("unused nodes", unused_nodes);
  line("duplicate nodes", duplicate_nodes);
  line("interface nodes off the boundary", off_boundary_nodes);
  line("attribute arrays of the wrong size", attribute_mismatch);
  for (const auto& p : problems) os << "  - " << p << "\n";
  if (n_problems > problems.size()) os << "  ... and " << n_problems - problems.size() << " more problems\n";
  return os.str();
}

namespace {

/// euler_characteristic of a solid of tetrahedra with four distinct nodes each, without sorting
/// all edges and faces: each edge and face is counted at its smallest node, edges by marking
/// the larger neighbours, faces by sorting the node's few (larger, larger) pairs. Empty when an
/// element is not such a tetrahedron (then the general count runs). The nodes in chunks on
/// n_threads threads, each with its own marks (integer counts: the same sum for every count;
/// serial, it was 0.12 s of sphere966 L6's 2.9 s on two threads).
std::optional<long> tet_euler_characteristic(const Mesh<3>& mesh, int n_threads, std::size_t run_uses) {
  const Elements& els = mesh.solid;
  const std::size_t n = mesh.points.size();
  std::atomic<bool> tets_only{true};
  for_each_range(els.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) {
      if (els.type[e] != ElemType::Tet4) return tets_only.store(false);
      const VertexId* v = els.nodes(ElemId{static_cast<std::int32_t>(e)});
      for (int i = 0; i < 4; ++i) {
        if (v[i].v < 0 || static_cast<std::size_t>(v[i].v) >= n) return tets_only.store(false);
        for (int j = i + 1; j < 4; ++j)
          if (v[i].v == v[j].v) return tets_only.store(false);
      }
    }
  });
  if (!tets_only.load()) return std::nullopt;
  // Each node's tetrahedra, listed for runs of nodes holding at most a quarter of the uses (a
  // pass over the tetrahedra a run): the lists of all nodes at once, 16 B a tetrahedron, were the
  // 3D pipeline's memory peak (its check before the quality stage, beside the octant complex:
  // sphere966 at 10^6 tetrahedra, 87 -> 102 MB resident).
  std::vector<std::int32_t> n_uses(n, 0);
  for (const VertexId v : els.node) ++n_uses[static_cast<std::size_t>(v.v)];
  const std::size_t cap = run_uses != 0 ? run_uses : std::max<std::size_t>(els.node.size() / 4, std::size_t(1) << 20);
  std::vector<std::int32_t> start, incident;
  std::atomic<long> total{0};
  for (std::size_t v0 = 0; v0 < n;) {
    std::size_t v1 = v0 + 1, uses = static_cast<std::size_t>(n_uses[v0]);
    while (v1 < n && uses + static_cast<std::size_t>(n_uses[v1]) <= cap) uses += static_cast<std::size_t>(n_uses[v1++]);
    const auto lo = static_cast<std::int32_t>(v0), hi = static_cast<std::int32_t>(v1);
    incidence_csr(
        v1 - v0, els.size(),
        [&](std::size_t e, auto&& f) {
          const VertexId* v = els.nodes(ElemId{static_cast<std::int32_t>(e)});
          for (int i = 0; i < 4; ++i)
            if (v[i].v >= lo && v[i].v < hi) f(v[i].v - lo);
        },
        n_threads, start, incident);
    for_each_chunk_balanced(v1 - v0, std::size_t(1) << 12, n_threads, [&](auto&& next) {
      std::vector<std::int32_t> mark(n, -1);
      std::vector<std::uint64_t> pairs;
      long nv = 0, ne = 0, nf = 0;
      for (std::size_t begin = 0, end = 0; next(begin, end);)
        for (std::size_t vi = begin; vi < end; ++vi) {
          if (start[vi] == start[vi + 1]) continue;
          const std::int32_t v = lo + static_cast<std::int32_t>(vi);
          ++nv;
          pairs.clear();
          for (std::int32_t k = start[vi]; k < start[vi + 1]; ++k) {
            const VertexId* t = els.nodes(ElemId{incident[k]});
            std::array<std::int32_t, 3> o{};
            int m = 0;
            for (int i = 0; i < 4; ++i)
              if (t[i].v != v) o[m++] = t[i].v;
            for (const std::int32_t u : o)
              if (u > v && mark[u] != v) mark[u] = v, ++ne;
            // The three faces through v: v with two of the other three nodes.
            for (int i = 0; i < 3; ++i) {
              const std::int32_t a = o[(i + 1) % 3], b = o[(i + 2) % 3];
              if (a > v && b > v)
                pairs.push_back(static_cast<std::uint64_t>(std::min(a, b)) << 32 | static_cast<std::uint32_t>(std::max(a, b)));
            }
          }
          std::sort(pairs.begin(), pairs.end());
          nf += std::unique(pairs.begin(), pairs.end()) - pairs.begin();
        }
      total += nv - ne + nf;
    });
    v0 = v1;
  }
  return total.load() - static_cast<long>(els.size());
}

}  // namespace

template <int Dim> long euler_characteristic(const Mesh<Dim>& mesh, int n_threads, std::size_t run_uses) {
  if constexpr (Dim == 3) {
    if (const std::optional<long> x = tet_euler_characteristic(mesh, n_threads, run_uses)) return *x;
  }
  return euler_characteristic_ref(mesh);
}

template <int Dim> long euler_characteristic_ref(const Mesh<Dim>& mesh) {
  std::vector<std::int32_t> used;
  used.reserve(mesh.solid.node.size());
  for (const VertexId v : mesh.solid.node) used.push_back(v.v);
  std::sort(used.begin(), used.end());
  const long v = std::unique(used.begin(), used.end()) - used.begin();
  const long e = static_cast<long>(unique_edges(mesh.solid).size());
  if constexpr (Dim == 2) {
    return v - e + static_cast<long>(mesh.solid.size());
  } else {
    const std::vector<FacetUse> uses = facet_uses(mesh.solid);
    long f = 0;
    for (std::size_t i = 0; i < uses.size(); ++i) f += (i == 0 || uses[i].key != uses[i - 1].key);
    return v - e + f - static_cast<long>(mesh.solid.size());
  }
}

template <int Dim> ValidationReport validate(const Mesh<Dim>& mesh, const ValidateOptions<Dim>& options) {
  ValidationReport r;
  Problems problems(r, options.max_problems);
  const auto& pts = mesh.points;
  r.n_points = pts.size();
  r.n_solid = mesh.solid.size();
  r.n_interface = mesh.interface.size();
  r.expected_euler = options.expected_euler;

  check_elements<Dim>(mesh.solid, Dim, "solid", pts.size(), r, problems);
  check_elements<Dim>(mesh.interface, Dim - 1, "interface", pts.size(), r, problems);
  for (const auto* attr : {&mesh.level, &mesh.from_boundary_cell}) {
    if (!attr->empty() && attr->size() != mesh.solid.size()) {
      ++r.attribute_mismatch;
      problems.add("attribute array of the wrong size", -1, [&](auto& os) {
        os << (attr == &mesh.level ? "level" : "from_boundary_cell") << " has " << attr->size() << " entries for "
           << mesh.solid.size() << " solid elements";
      });
    }
  }
  if (r.bad_elements != 0) return r;  // the checks below index nodes and tables by element type

  // The checks below look at each element, node, edge or facet on its own: on n_threads, the
  // ones that fail are marked, then reported in order on this thread (the same report).
  const auto marked = [&](std::size_t n, const auto& fails) {
    std::vector<std::uint8_t> mark(n, 0);
    for_each_range(n, options.n_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) mark[i] = fails(i) ? 1 : 0;
    });
    return mark;
  };

  // Orientation: every corner.
  const auto corner_jacobian = [&](std::size_t e) {
    const auto ep = element_points<Dim>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, pts);
    return min_corner_jacobian<Dim>(mesh.solid.type[e], ep.span());
  };
  const std::vector<std::uint8_t> inverted = marked(mesh.solid.size(), [&](std::size_t e) { return !(corner_jacobian(e) > 0.0); });
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    if (!inverted[e]) continue;
    const double j = corner_jacobian(e);
    ++r.inverted;
    problems.add("an element is inverted", mesh.solid.nodes(ElemId{static_cast<std::int32_t>(e)})[0].v, [&](auto& os) {
      os << "inverted solid " << fmt_element<Dim>(mesh.solid, e, pts) << ": min corner Jacobian " << j;
    });
  }

  // Conformity: group facet uses by key.
  std::vector<FacetUse> boundary;  // used once; sorted by key
  std::size_t n_unique_facets = 0;  // (a count: the list of keys was 24 B/element at the CLI's peak)
  // 3D: each distinct facet's first use, in key order, for the hanging-node check below (the
  // groups are freed after this loop, not kept to the end beside the edge list), 4 bytes each:
  // element << 3 | local facet.
  if (Dim == 3 && mesh.solid.size() >= (std::size_t(1) << 29))
    throw std::length_error("validate: more than 2^29 solid elements (" + std::to_string(mesh.solid.size()) + ")");
  std::vector<std::uint32_t> first_uses;
  [[maybe_unused]] const auto first_elem = [&](std::size_t i) { return ElemId{static_cast<std::int32_t>(first_uses[i] >> 3)}; };
  [[maybe_unused]] const auto first_local = [&](std::size_t i) { return static_cast<int>(first_uses[i] & 7u); };
  // The solid's edges: the hanging-node check and the Euler characteristic (one list, not two:
  // it was 3% of the 2D CLI's instructions). Of triangles and quads, the facet groups' keys (2D:
  // unique_edges was 0.12 s of the validation's 0.44 at flange 968,326 triangles, one thread).
  std::vector<std::array<VertexId, 2>> edges;
  bool edges_listed = false;
  {
    const FacetGroups groups(mesh.solid, options.n_threads, options.bucketed_facets);
    n_unique_facets = groups.n_groups();
    if constexpr (Dim == 3) first_uses.resize(n_unique_facets);
    edges_listed = Dim == 2 && groups.polygons();
    if (edges_listed) edges.resize(n_unique_facets);
    // Each chunk of the groups lists its boundary facets and the groups that do not conform
    // apart; they join in chunk order (key order), and the latter are reported in that order.
    std::vector<std::vector<FacetUse>> boundary_in(groups.n_chunks());
    std::vector<std::vector<std::vector<FacetUse>>> bad_in(groups.n_chunks());
    groups.for_each(options.n_threads, [&](std::size_t c, std::size_t i, std::span<const FacetUse> g) {
      if (edges_listed) edges[i] = {VertexId{g[0].key.v[0]}, VertexId{g[0].key.v[1]}};
      if constexpr (Dim == 3) first_uses[i] = static_cast<std::uint32_t>(g[0].elem.v) << 3 | static_cast<std::uint32_t>(g[0].local);
      if (g.size() == 1) {
        boundary_in[c].push_back(g[0]);
      } else if (g.size() > 2 || g[0].orientation == g[1].orientation) {
        bad_in[c].emplace_back(g.begin(), g.end());
      }
    });
    std::size_t n_boundary = 0;
    for (const auto& b : boundary_in) n_boundary += b.size();
    boundary.reserve(n_boundary);
    for (std::size_t c = 0; c < groups.n_chunks(); ++c) {
      boundary.insert(boundary.end(), boundary_in[c].begin(), boundary_in[c].end());
      std::vector<FacetUse>().swap(boundary_in[c]);
      for (const std::vector<FacetUse>& g : bad_in[c]) {
        ++r.nonconforming_facets;
        problems.add("a facet does not conform", g[0].key.v[0], [&](auto& os) {
          os << "facet " << fmt_key(g[0].key) << " used " << g.size() << " times"
             << (g.size() == 2 ? " in the same orientation" : "") << " by solid elements";
          for (const FacetUse& u : g) os << " " << u.elem.v;
          os << " at " << fmt<Dim>(pts[g[0].key.v[0]]);
        });
      }
    }
  }

  // A quad facet against two triangles on its four nodes (a hex beside two tets) leaves all three
  // used once, so the grouping above cannot see it, and an interface listing all three would match.
  {
    const auto is_boundary = [&](VertexId a, VertexId b, VertexId c) {
      Facet t;
      t.type = ElemType::Tri3;
      t.n = 3;
      t.node = {a, b, c, VertexId{}};
      const FacetKey k = key_of(t);
      return std::binary_search(boundary.begin(), boundary.end(), k,
                                [](const auto& x, const auto& y) {
                                  if constexpr (std::is_same_v<std::decay_t<decltype(x)>, FacetKey>) return x < y.key;
                                  else return x.key < y;
                                });
    };
    for (const FacetUse& q : boundary) {
      if (q.key.v[3] < 0) continue;
      const Facet f = facet_of(mesh.solid, q.elem, q.local);
      for (int d = 0; d < 2; ++d) {
        const VertexId a = f.node[d], b = f.node[d + 1], c = f.node[(d + 2) % 4], e = f.node[(d + 3) % 4];
        if (!is_boundary(a, b, c) || !is_boundary(a, c, e)) continue;
        ++r.nonconforming_facets;
        problems.add("a facet does not conform", q.key.v[0], [&](auto& os) {
          os << "quad facet " << fmt_key(q.key) << " of solid element " << q.elem.v
             << " meets two triangles on its nodes, at " << fmt<Dim>(pts[q.key.v[0]]);
        });
        break;
      }
    }
  }

  // Interface == boundary facets, same orientation.
  if (options.check_interface) {
    std::vector<char> matched(boundary.size(), 0);
    for (std::size_t e = 0; e < mesh.interface.size(); ++e) {
      const Facet f = as_facet(mesh.interface, ElemId{static_cast<std::int32_t>(e)});
      const FacetKey k = key_of(f);
      const auto it = std::lower_bound(boundary.begin(), boundary.end(), k,
                                       [](const FacetUse& u, const FacetKey& key) { return u.key < key; });
      const std::size_t bi = static_cast<std::size_t>(it - boundary.begin());
      if (it == boundary.end() || it->key != k || matched[bi]) {
        ++r.interface_extra;
        problems.add("an interface element is not a boundary facet", mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)})[0].v, [&](auto& os) {
          os << "interface " << fmt_element<Dim>(mesh.interface, e, pts)
             << (it != boundary.end() && it->key == k ? " repeats a boundary facet" : " is not a boundary facet of the solid");
        });
        continue;
      }
      matched[bi] = 1;
      if (orientation_of(f) != it->orientation) {
        ++r.interface_reversed;
        problems.add("an interface element is reversed", mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)})[0].v, [&](auto& os) {
          os << "interface " << fmt_element<Dim>(mesh.interface, e, pts) << " is reversed (against solid element "
             << it->elem.v << ")";
        });
      }
    }
    for (std::size_t b = 0; b < boundary.size(); ++b) {
      if (matched[b]) continue;
      ++r.interface_missing;
      problems.add("a boundary facet has no interface element", boundary[b].key.v[0], [&](auto& os) {
        os << "boundary facet " << fmt_key(boundary[b].key) << " of solid element " << boundary[b].elem.v
           << " has no interface element, at " << fmt<Dim>(pts[boundary[b].key.v[0]]);
      });
    }
    r.interface_mismatch = r.interface_missing + r.interface_extra + r.interface_reversed;
  }

  // Node usage.
  std::vector<char> used(pts.size(), 0), solid_used(pts.size(), 0);
  for (const VertexId v : mesh.solid.node) used[v.v] = solid_used[v.v] = 1;
  for (const VertexId v : mesh.interface.node) used[v.v] = 1;
  std::vector<std::int32_t> used_ids;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (used[i]) {
      used_ids.push_back(static_cast<std::int32_t>(i));
      continue;
    }
    ++r.unused_nodes;
    problems.add("a node is unused", static_cast<std::int32_t>(i), [&](auto& os) { os << "node " << i << " at " << fmt<Dim>(pts[i]) << " is used by no element"; });
  }

  // A uniform grid answers the queries (PointGrid says why; in 3D the k-d tree's node queries
  // were 15% of the instructions of a whole sphere966 level-4 CLI run, measured by callgrind);
  // the k-d tree is built only to report an edge with several hanging nodes in its order.
  std::optional<PointTree<Dim>> tree;
  const PointGrid<Dim> grid(pts, used_ids);

  // Duplicate nodes (the smallest id within tol: the same whatever the order of the visits).
  {
    Box<Dim> all = Box<Dim>::empty();
    for (const auto id : used_ids) all.expand(pts[id]);
    const double tol = used_ids.empty() ? 0.0 : options.duplicate_rel_tol * all.extent().norm();
    const auto first_within = [&](std::int32_t i) {
      std::int32_t first = i;
      grid.query(inflated_box<Dim>({pts[i]}, tol), [&](std::int32_t j) {
        if (j < first && (pts[j] - pts[i]).norm() <= tol) first = j;
      });
      return first;
    };
    const std::vector<std::uint8_t> duplicate =
        marked(used_ids.size(), [&](std::size_t k) { return first_within(used_ids[k]) != used_ids[k]; });
    for (std::size_t k = 0; k < used_ids.size(); ++k) {
      if (!duplicate[k]) continue;
      const std::int32_t i = used_ids[k], first = first_within(i);
      ++r.duplicate_nodes;
      problems.add("a node is duplicated", i, [&](auto& os) { os << "node " << i << " duplicates node " << first << " at " << fmt<Dim>(pts[i]); });
    }
  }

  if (!edges_listed) edges = unique_edges(mesh.solid, 0, options.n_threads);

  // Hanging nodes: on the interior of an edge (both dimensions) or of a facet (3D).
  {
    const double rel = options.hanging_rel_tol;
    std::vector<char> hanging(pts.size(), 0);
    auto report = [&](std::int32_t c, const std::string& where) {
      if (hanging[c]) return;
      hanging[c] = 1;
      ++r.hanging_nodes;
      problems.add("a node hangs on an edge or facet", c, [&](auto& os) { os << "hanging node " << c << " at " << fmt<Dim>(pts[c]) << " on " << where; });
    };
    // Edge k's box, and whether node c lies on its interior.
    const auto edge_box = [&](std::size_t k) {
      const Point<Dim>&pa = pts[edges[k][0].v], &pb = pts[edges[k][1].v];
      return inflated_box<Dim>({pa, pb}, rel * (pb - pa).norm());
    };
    const auto on_edge = [&](std::size_t k, std::int32_t c) {
      const VertexId a = edges[k][0], b = edges[k][1];
      return c != a.v && c != b.v && on_open_segment<Dim>(pts[c], pts[a.v], pts[b.v], rel);
    };
    const std::vector<std::uint8_t> edge_hit = marked(edges.size(), [&](std::size_t k) {
      bool hit = false;
      grid.query(edge_box(k), [&](std::int32_t c) { hit = hit || on_edge(k, c); });
      return hit;
    });
    std::vector<std::int32_t> hits;
    for (std::size_t k = 0; k < edges.size(); ++k) {
      if (!edge_hit[k]) continue;
      const Box<Dim> box = edge_box(k);
      auto report_edge = [&](std::int32_t c) {
        report(c, "edge " + std::to_string(edges[k][0].v) + "-" + std::to_string(edges[k][1].v));
      };
      hits.clear();
      grid.query(box, [&](std::int32_t c) {
        if (on_edge(k, c)) hits.push_back(c);
      });
      if (hits.size() == 1) {
        report_edge(hits[0]);
      } else if (hits.size() > 1) {  // the k-d tree's order, as the reports always came
        if (!tree) tree.emplace(pts, used_ids);
        tree->query(box, [&](std::int32_t c) {
          if (on_edge(k, c)) report_edge(c);
        });
      }
    }
    if constexpr (Dim == 3) {
      // Calls at(c) for every node c on the interior of the i-th distinct facet.
      const auto on_interior = [&](std::size_t i, const auto& at) {
        const Facet f = facet_of(mesh.solid, first_elem(i), first_local(i));
        Box<3> box = Box<3>::empty();
        for (int k = 0; k < f.n; ++k) box.expand(pts[f.node[k].v]);
        const double h = facet_size(f, pts);  // once per facet, not once per node tested
        box.lo.array() -= rel * h;
        box.hi.array() += rel * h;
        if (f.n == 3) {
          const TriangleInterior tri(pts[f.node[0].v], pts[f.node[1].v], pts[f.node[2].v], h, rel);
          grid.query(box, [&](std::int32_t c) {
            if (c != f.node[0].v && c != f.node[1].v && c != f.node[2].v && tri.contains(pts[c])) at(c);
          });
          return;
        }
        grid.query(box, [&](std::int32_t c) {
          for (int k = 0; k < f.n; ++k)
            if (f.node[k].v == c) return;
          if (on_quad_interior(pts[c], f, h, pts, rel)) at(c);
        });
      };
      // Whether some node lies on each facet's interior. Of tetrahedra, one grid query a
      // tetrahedron for the facets whose first use it is (about two: the query per facet was most
      // of this check), each candidate then tested against each facet's own box and plane: the
      // nodes each facet's query gives, so the same marks.
      const bool all_tets = options.bucketed_facets && std::all_of(mesh.solid.type.begin(), mesh.solid.type.end(),
                                                                   [](ElemType t) { return t == ElemType::Tet4; });
      std::vector<std::uint8_t> facet_hit;
      if (all_tets) {
        std::vector<std::uint8_t> firsts(mesh.solid.size(), 0), hits(mesh.solid.size(), 0);
        for (const std::uint32_t u : first_uses) firsts[u >> 3] |= static_cast<std::uint8_t>(1u << (u & 7u));
        for_each_range(mesh.solid.size(), options.n_threads, [&](std::size_t begin, std::size_t end) {
          for (std::size_t e = begin; e < end; ++e) {
            if (firsts[e] == 0) continue;
            struct Side {
              Facet f;
              Box<3> box;
              TriangleInterior tri;
              std::uint8_t bit;
            };
            std::array<std::optional<Side>, 4> sides;
            Box<3> all = Box<3>::empty();
            for (int k = 0; k < 4; ++k) {
              if (!(firsts[e] >> k & 1u)) continue;
              const Facet f = facet_of(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, k);
              Box<3> box = Box<3>::empty();
              for (int j = 0; j < 3; ++j) box.expand(pts[f.node[j].v]);
              const double h = facet_size(f, pts);
              box.lo.array() -= rel * h;
              box.hi.array() += rel * h;
              all.expand(box.lo);
              all.expand(box.hi);
              sides[k].emplace(Side{f, box, TriangleInterior(pts[f.node[0].v], pts[f.node[1].v], pts[f.node[2].v], h, rel),
                                    static_cast<std::uint8_t>(1u << k)});
            }
            std::uint8_t hit = 0;
            const auto test = [&](std::int32_t c, std::uint8_t only) {
              for (const std::optional<Side>& side : sides) {
                if (!side || !(side->bit & only) || (hit & side->bit) || !side->box.contains(pts[c])) continue;
                const Facet& f = side->f;
                if (c != f.node[0].v && c != f.node[1].v && c != f.node[2].v && side->tri.contains(pts[c])) hit |= side->bit;
              }
            };
            if (all.lo.allFinite() && all.hi.allFinite()) {
              grid.query(all, [&](std::int32_t c) { test(c, 0xf); });
            } else {  // (a node not finite: each facet's own query, as the twin does)
              for (const std::optional<Side>& side : sides)
                if (side) grid.query(side->box, [&](std::int32_t c) { test(c, side->bit); });
            }
            hits[e] = hit;
          }
        });
        facet_hit.resize(first_uses.size());
        for (std::size_t i = 0; i < first_uses.size(); ++i) facet_hit[i] = hits[first_uses[i] >> 3] >> (first_uses[i] & 7u) & 1u;
      } else {
        facet_hit = marked(first_uses.size(), [&](std::size_t i) {
          bool hit = false;
          on_interior(i, [&](std::int32_t) { hit = true; });
          return hit;
        });
      }
      for (std::size_t i = 0; i < first_uses.size(); ++i)
        if (facet_hit[i]) {
          // In node order, whatever the grid's cells (PointGrid sizes them by the points).
          hits.clear();
          on_interior(i, [&](std::int32_t c) { hits.push_back(c); });
          std::sort(hits.begin(), hits.end());
          for (const std::int32_t c : hits)
            report(c, "facet " + fmt_key(key_of(facet_of(mesh.solid, first_elem(i), first_local(i)))));
        }
    }
  }

  // Interface nodes on the boundary.
  if (options.boundary_distance) {
    std::vector<std::int32_t> nodes;
    for (const VertexId v : mesh.interface.node) nodes.push_back(v.v);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    std::vector<double> distance(nodes.size());
    for_each_range(nodes.size(), options.n_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) distance[k] = std::abs(options.boundary_distance(pts[nodes[k]]));
    });
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const std::int32_t v = nodes[k];
      const double d = distance[k];
      r.max_boundary_distance = std::max(r.max_boundary_distance, d);
      if (!(d <= options.boundary_tolerance)) {
        ++r.off_boundary_nodes;
        problems.add(off_boundary_kind, v, [&](auto& os) {
          os << "interface node " << v << " at " << fmt<Dim>(pts[v]) << " is " << d << " from the boundary";
        });
      }
    }
  }

  // Euler characteristic of the solid.
  {
    const long v = std::accumulate(solid_used.begin(), solid_used.end(), 0L);
    const long e = static_cast<long>(edges.size());
    r.euler = Dim == 2 ? v - e + static_cast<long>(mesh.solid.size())
                       : v - e + static_cast<long>(n_unique_facets) - static_cast<long>(mesh.solid.size());
    if (options.expected_euler && *options.expected_euler != r.euler)
      problems.add("the Euler characteristic differs", -1, [&](auto& os) { os << "Euler characteristic " << r.euler << ", expected " << *options.expected_euler; });
  }

  if (mesh.solid.size() == 0) problems.add("the mesh is empty", -1, [&](auto& os) { os << "no solid elements"; });
  r.valid = r.conforms() && r.off_boundary_nodes == 0 && (!options.expected_euler || *options.expected_euler == r.euler);
  return r;
}

template <int Dim> std::uint64_t content_hash(const Mesh<Dim>& mesh) {
  FnvLanes h;
  // Each array's size, then its bytes as 32-bit words (the bytes of a last partial word one by one).
  const auto add = [&h](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    h.add(v.size());
    const std::size_t n_bytes = v.size() * sizeof(T);
    const auto* bytes = reinterpret_cast<const unsigned char*>(v.data());
    std::size_t b = 0;
    for (; b + 4 <= n_bytes; b += 4) {
      std::uint32_t x;
      std::memcpy(&x, bytes + b, 4);
      h.add(x);
    }
    for (; b < n_bytes; ++b) h.add(bytes[b]);
  };
  static_assert(sizeof(Point<Dim>) == Dim * sizeof(double), "points are packed doubles");
  add(mesh.points);
  for (const Elements* els : {&mesh.solid, &mesh.interface}) {
    add(els->type);
    add(els->offset);
    add(els->node);
  }
  add(mesh.level);
  add(mesh.from_boundary_cell);
  return h.value();
}

template <int Dim> bool is_valid(const Mesh<Dim>& mesh, const ValidateOptions<Dim>& options) {
  return validate<Dim>(mesh, options).valid;
}

template ValidationReport validate<2>(const Mesh<2>&, const ValidateOptions<2>&);
template ValidationReport validate<3>(const Mesh<3>&, const ValidateOptions<3>&);
template std::uint64_t content_hash<2>(const Mesh<2>&);
template std::uint64_t content_hash<3>(const Mesh<3>&);
template bool is_valid<2>(const Mesh<2>&, const ValidateOptions<2>&);
template bool is_valid<3>(const Mesh<3>&, const ValidateOptions<3>&);
template long euler_characteristic<2>(const Mesh<2>&, int, std::size_t);
template long euler_characteristic<3>(const Mesh<3>&, int, std::size_t);
template long euler_characteristic_ref<2>(const Mesh<2>&);
template long euler_characteristic_ref<3>(const Mesh<3>&);

}  // namespace febemesh
