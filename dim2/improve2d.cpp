#include "dim2/improve2d.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/guard_order.hpp"
#include "core/huge_pages.hpp"
#include "core/mesh_topology.hpp"
#include "core/parallel_ranges.hpp"
#include "core/partitioned_sweep.hpp"
#include "core/radix_sort_lsd.hpp"
#include "core/smooth.hpp"

namespace febemesh::dim2 {
namespace {

using P2 = Point<2>;

double cross(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/// Corner angle (degrees) from its cross and dot products.
double corner_angle(double cr, double dot) { return std::atan2(std::abs(cr), dot) * 180.0 / M_PI; }

/// Slow twin of polygon_min_angle_n: every corner's atan2.
double polygon_min_angle_ref(const P2* pts, int n) {
  double best = 180.0;
  for (int k = 0; k < n; ++k) {
    const P2 &prev = pts[(k + n - 1) % n], &cur = pts[k], &next = pts[(k + 1) % n];
    if (cross(prev, cur, next) <= 0) return -1.0;
    const P2 a = prev - cur, b = next - cur;
    best = std::min(best, corner_angle(a[0] * b[1] - a[1] * b[0], a.dot(b)));
  }
  return best;
}

/// Smallest corner angle of polygon pts (CCW), degrees; -1 if any corner turns the wrong way.
/// Cost: the angle is decreasing in its cotangent dot/|cross|, so atan2 runs only for the
/// corners whose cotangent is within a margin of the largest (ties and near-ties: all of them).
/// The margin (1e-7 relative) dwarfs the rounding of the quotients and of atan2, so the minimum
/// is the one polygon_min_angle_ref takes, bit for bit. n (3 or 4) is a template parameter so
/// that the loops unroll.
template <int n> double polygon_min_angle_n(const P2* pts) {
  double cr[n], dot[n], cot[n];
  for (int k = 0; k < n; ++k) {
    const P2 &prev = pts[(k + n - 1) % n], &cur = pts[k], &next = pts[(k + 1) % n];
    if (cross(prev, cur, next) <= 0) return -1.0;
    const P2 a = prev - cur, b = next - cur;
    cr[k] = std::abs(a[0] * b[1] - a[1] * b[0]);
    dot[k] = a.dot(b);
    if (!(cr[k] > 0) || !std::isfinite(dot[k])) return polygon_min_angle_ref(pts, n);
    cot[k] = dot[k] / cr[k];
  }
  double top = cot[0];
  for (int k = 1; k < n; ++k) top = std::max(top, cot[k]);
  const double margin = 1e-7 * (1.0 + std::abs(top));
  double best = 180.0;
  for (int k = 0; k < n; ++k)
    if (cot[k] >= top - margin) best = std::min(best, corner_angle(cr[k], dot[k]));
  return best;
}

double tri_min_angle(const P2& a, const P2& b, const P2& c) {
  const P2 p[3] = {a, b, c};
  return polygon_min_angle_n<3>(p);
}

/// min_corner_angle_deg, inlined where the quality pass evaluates its trials.
inline double element_min_angle(const Mesh<2>& m, std::size_t e) {
  const VertexId* v = m.solid.node.data() + m.solid.offset[e];
  if (m.solid.offset[e + 1] - m.solid.offset[e] == 3) {
    const P2 p[3] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v]};
    return polygon_min_angle_n<3>(p);
  }
  MESH_ASSERT(m.solid.offset[e + 1] - m.solid.offset[e] == 4, "element " << e);
  const P2 p[4] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]};
  return polygon_min_angle_n<4>(p);
}

/// The largest corner cotangent of polygon pts (CCW): the smallest angle falls as it rises.
/// +inf when polygon_min_angle_n gives -1 (a corner turns the wrong way), NaN when only
/// polygon_min_angle_n can tell (a flat corner, non-finite coordinates).
template <int n> double polygon_top_cot(const P2* pts) {
  double top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < n; ++k) {
    const P2 &prev = pts[(k + n - 1) % n], &cur = pts[k], &next = pts[(k + 1) % n];
    if (cross(prev, cur, next) <= 0) return std::numeric_limits<double>::infinity();
    const P2 a = prev - cur, b = next - cur;
    const double cr = std::abs(a[0] * b[1] - a[1] * b[0]), dot = a.dot(b);
    if (!(cr > 0) || !std::isfinite(dot)) return std::numeric_limits<double>::quiet_NaN();
    top = std::max(top, dot / cr);
  }
  return top;
}

/// polygon_top_cot<3> from the three edge vectors e[k] = p[k+1] - p[k], computed once: every
/// difference the corner loop takes is one of them or its negation (p[k-1] - p[k] = -e[k-1], and
/// in a triangle p[k+1] - p[k-1] = -e[k+1]), and rounding is symmetric (fl(x - y) = -fl(y - x)),
/// so each corner's cross, |cross| and dot are the same bits, checked in the same order.
/// 6 subtractions where the loop took 18 (the quality pass's hottest function, flange level 9).
template <> double polygon_top_cot<3>(const P2* pts) {
  const double ex[3] = {pts[1][0] - pts[0][0], pts[2][0] - pts[1][0], pts[0][0] - pts[2][0]};
  const double ey[3] = {pts[1][1] - pts[0][1], pts[2][1] - pts[1][1], pts[0][1] - pts[2][1]};
  double top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const int u = (k + 2) % 3, w = (k + 1) % 3;  // cur - prev = e[u], next - prev = -e[w], next - cur = e[k]
    if (ey[u] * ex[w] - ex[u] * ey[w] <= 0) return std::numeric_limits<double>::infinity();
    const double cr = std::abs(ey[u] * ex[k] - ex[u] * ey[k]), dot = -(ex[u] * ex[k] + ey[u] * ey[k]);
    if (!(cr > 0) || !std::isfinite(dot)) return std::numeric_limits<double>::quiet_NaN();
    top = std::max(top, dot / cr);
  }
  return top;
}

inline double element_top_cot(const Mesh<2>& m, std::size_t e) {
  const VertexId* v = m.solid.node.data() + m.solid.offset[e];
  if (m.solid.offset[e + 1] - m.solid.offset[e] == 3) {
    const P2 p[3] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v]};
    return polygon_top_cot<3>(p);
  }
  const P2 p[4] = {m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]};
  return polygon_top_cot<4>(p);
}

/// Whether angle a exceeds angle b + eps (degrees, 0 <= eps <= 1e-6), where ca and cb are the
/// angles' cotangents (as polygon_top_cot gives them) and exact_a / exact_b their degrees as
/// polygon_min_angle_n gives them. For ca < cb, acot(ca) - acot(cb) = integral of 1 / (1 + c^2)
/// over [ca, cb], between (cb - ca) / (1 + max c^2) and (cb - ca) / (1 + min c^2) (min c^2 = 0
/// when the signs differ). The degrees are acot of the cotangent up to ~2e-15 rad each (the
/// quotient's rounding, atan2's 1-2 ulp, the two roundings of * 180 / pi; an element's smallest
/// angle is its largest cotangent's, up to those), so when those bounds clear eps (in radians)
/// by 8e-15 either way the degrees decide the same; only the rest (and non-finite cotangents)
/// are decided on the exact degrees, computed only then (atan2 is most of an angle's cost).
template <class A, class B> bool exceeds(double ca, A&& exact_a, double cb, B&& exact_b, double eps) {
  if (std::isfinite(ca) && std::isfinite(cb)) {
    constexpr double slack = 8e-15;
    const double d = cb - ca, e = eps * (M_PI / 180.0);
    const double hi2 = std::max(ca * ca, cb * cb), lo2 = (ca > 0) == (cb > 0) ? std::min(ca * ca, cb * cb) : 0.0;
    const double lower = d / (1.0 + (d >= 0 ? hi2 : lo2));
    if (lower > e + slack) return true;
    const double upper = d / (1.0 + (d >= 0 ? lo2 : hi2));
    if (upper < e - slack) return false;
  }
  return exact_a() > exact_b() + eps;
}

}  // namespace

double min_corner_angle_deg(const Mesh<2>& m, std::size_t e) { return element_min_angle(m, e); }

double min_corner_angle_deg_ref(const Mesh<2>& m, std::size_t e) {
  const ElemId id{static_cast<std::int32_t>(e)};
  const int n = m.solid.n_nodes_of(id);
  std::array<P2, 4> p;
  for (int k = 0; k < n; ++k) p[k] = m.points[m.solid.nodes(id)[k].v];
  return polygon_min_angle_ref(p.data(), n);
}

namespace {

/// Node -> incident elements, kept up to date under edge flips instead of rebuilt for every
/// flip pass and smoothing round (flange level 9: 13 rebuilds, each two sweeps over all
/// elements, were 15% of this stage's instructions). A list's order is not kept (removal moves
/// the last in): every use below reads a list as a set (the flip pass finds an edge's two
/// triangles and orders them by id; the smoothing's decisions are over all of a node's
/// elements, its sums over its sorted neighbours). CSR with two spare slots per node, unused
/// slots -1, and no per-node counts: with counts and room per node (12 B/node more) this stage
/// was the memory peak at flange level 10 (120 B/element; now 104). A flip that finds a list
/// full moves that list out, to a vector of its own (one spare slot: 4 rebuilds of everything
/// at flange level 9, +200M instructions; two: none, 1.17G for the stage against 1.44G before
/// the live lists). The moved list's slots keep a mark, -2 - its index among the moved ones,
/// in the first, the rest -1; of() sees the mark only where it finds no element, so the usual
/// lists pay nothing for it. (The moves replaced a rebuild of everything from the mesh, which
/// NimbusSans U0067 at 10^6 triangles, 486,000 nodes, needed once: the stage took 0.1683 s
/// with it and 0.1658 without, medians of 6 alternating runs on one thread.)
class LiveIncidence {
 public:
  /// The lists add() would make of the elements in increasing order (each list ascending, then
  /// its spare slots), filled from the back: first_[v] starts at the end of v's uses and steps
  /// down to its start, one store a use instead of add's search for the first free slot.
  /// On n_threads threads, each owning a range of nodes and reading every element for them
  /// (the same lists; the serial build was most of this stage's set-up, 0.08 s of 0.13 at
  /// flange 1e6).
  explicit LiveIncidence(const Mesh<2>& m, int n_threads = 1) {
    const std::size_t n = m.points.size();
    reserve_huge(first_, n + 1, n_threads);
    first_.resize(n + 1);
    const auto owned = [&](std::size_t lo, std::size_t hi, auto&& use) {
      const auto l = static_cast<std::int32_t>(lo), h = static_cast<std::int32_t>(hi);
      if (lo == 0 && hi == n) {
        for (std::size_t e = m.solid.size(); e-- > 0;)
          for (std::int32_t k = m.solid.offset[e + 1]; k-- > m.solid.offset[e];) use(e, m.solid.node[k].v);
        return;
      }
      for (std::size_t e = m.solid.size(); e-- > 0;)
        for (std::int32_t k = m.solid.offset[e + 1]; k-- > m.solid.offset[e];)
          if (const std::int32_t v = m.solid.node[k].v; v >= l && v < h) use(e, v);
    };
    for_each_range(n, n_threads, [&](std::size_t lo, std::size_t hi) {
      std::fill(first_.begin() + lo, first_.begin() + hi, 0);
      owned(lo, hi, [&](std::size_t, std::int32_t v) { ++first_[static_cast<std::size_t>(v)]; });
    });
    std::int32_t start = 0;
    for (std::size_t v = 0; v < n; ++v) {
      const std::int32_t uses = first_[v];
      first_[v] = start + uses;
      start += uses + spare;
    }
    first_[n] = start;
    reserve_huge(elem_, static_cast<std::size_t>(start), n_threads);
    elem_.resize(static_cast<std::size_t>(start));
    for_each_range(n, n_threads, [&](std::size_t lo, std::size_t hi) {
      for (std::size_t v = lo; v < hi; ++v)  // the spare slots, after the uses
        std::fill_n(elem_.begin() + first_[v], spare, -1);
      owned(lo, hi, [&](std::size_t e, std::int32_t v) {
        elem_[static_cast<std::size_t>(--first_[static_cast<std::size_t>(v)])] = static_cast<std::int32_t>(e);
      });
    });
  }
  /// A list is a prefix of its slots (add fills the first free one, remove moves the last in):
  /// its end is found from the back, where most lists have their spare slots free.
  std::span<const std::int32_t> of(std::int32_t v) const {
    const std::int32_t* list = elem_.data() + first_[v];
    auto n = static_cast<std::size_t>(first_[v + 1] - first_[v]);
    while (n > 0 && list[n - 1] < 0) --n;
    if (n == 0)  // (every node has 2+ slots)
      if (const std::int32_t k = moved_index(list); k >= 0) return moved_[static_cast<std::size_t>(k)];
    return {list, n};
  }
  void add(std::int32_t v, std::int32_t e) {
    std::int32_t* list = elem_.data() + first_[v];
    const std::int32_t slots = first_[v + 1] - first_[v];
    if (const std::int32_t k = moved_index(list); k >= 0) return moved_[static_cast<std::size_t>(k)].push_back(e);
    for (std::int32_t k = 0; k < slots; ++k)
      if (list[k] < 0) return void(list[k] = e);
    moved_.emplace_back(list, list + slots).push_back(e);  // full: moved out
    std::fill_n(list, slots, -1);
    list[0] = -1 - static_cast<std::int32_t>(moved_.size());
  }
  /// Requires e in v's list.
  void remove(std::int32_t v, std::int32_t e) {
    std::int32_t* list = elem_.data() + first_[v];
    if (const std::int32_t k = moved_index(list); k >= 0) {
      std::vector<std::int32_t>& moved = moved_[static_cast<std::size_t>(k)];
      const auto it = std::find(moved.begin(), moved.end(), e);
      MESH_ASSERT(it != moved.end(), "element " << e << " not at node " << v);
      *it = moved.back();
      moved.pop_back();
      return;
    }
    const auto n = static_cast<std::int32_t>(of(v).size());
    std::int32_t k = 0;
    while (list[k] != e) ++k;
    MESH_ASSERT(k < n, "element " << e << " not at node " << v);
    list[k] = list[n - 1];
    list[n - 1] = -1;
  }

 private:
  static constexpr std::int32_t spare = 2;
  std::vector<std::int32_t> first_, elem_;
  std::vector<std::vector<std::int32_t>> moved_;  ///< the lists that outgrew their slots
  /// The index in moved_ of the list a node's slots (starting at `list`) hand over to, by the
  /// mark in the first; -1 where they hold the list themselves.
  static std::int32_t moved_index(const std::int32_t* list) { return list[0] < -1 ? -2 - list[0] : -1; }
};

/// The exact degrees of some elements, by element id (direct-mapped), for improve_mesh.
struct Memo {
  static constexpr std::size_t n = 4096;
  std::vector<std::int32_t> elem = std::vector<std::int32_t>(n, -1);
  std::vector<double> deg = std::vector<double>(n);
  void clear() { std::fill(elem.begin(), elem.end(), -1); }
};

/// Whether a flip's four nodes lie in two slabs or more (then they all become separators, in
/// improve_mesh and its twin).
bool spans_parts(const std::vector<std::uint8_t>& part, std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
  const std::uint8_t p = part[static_cast<std::size_t>(a)];
  return part[static_cast<std::size_t>(b)] != p || part[static_cast<std::size_t>(c)] != p || part[static_cast<std::size_t>(d)] != p;
}

/// Local index k of triangle v with {v[k], v[k+1]} == {a, b}, or -1.
int local_edge(const VertexId* v, std::int32_t a, std::int32_t b) {
  for (int k = 0; k < 3; ++k) {
    const std::int32_t p = v[k].v, q = v[(k + 1) % 3].v;
    if ((p == a && q == b) || (p == b && q == a)) return k;
  }
  return -1;
}

}  // namespace

// Cost: the smallest angles are cached per element and refreshed only where a node moved or an
// edge flipped, candidate edges are those of elements below `good`, and adjacency is CSR built
// once per pass; the visiting order (edges by key, nodes by index) is the plain algorithm's, so
// the result is the same as recomputing everything.
InterfaceNeighbours interface_neighbours(const Mesh<2>& m) {
  InterfaceNeighbours out;
  out.first.assign(m.points.size() + 1, 0);
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    ++out.first[v[0].v + 1];
    ++out.first[v[1].v + 1];
  }
  for (std::size_t v = 0; v + 1 < out.first.size(); ++v) out.first[v + 1] += out.first[v];
  std::vector<std::int32_t> nbr(static_cast<std::size_t>(out.first.back()));
  // Filled with first[v] as v's cursor, which ends at the next node's start; then moved back
  // one place (no copy of the n + 1 starts as cursors).
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    nbr[out.first[v[0].v]++] = v[1].v;
    nbr[out.first[v[1].v]++] = v[0].v;
  }
  for (std::size_t v = out.first.size() - 1; v > 0; --v) out.first[v] = out.first[v - 1];
  out.first[0] = 0;
  // Sorted and deduplicated per node, compacted in place.
  out.nbr.reserve(nbr.size());
  for (std::size_t v = 0; v + 1 < out.first.size(); ++v) {
    const auto b = nbr.begin() + out.first[v], e = nbr.begin() + out.first[v + 1];
    std::sort(b, e);
    out.first[v] = static_cast<std::int32_t>(out.nbr.size());
    for (auto it = b; it != e; ++it)
      if (it == b || *it != *(it - 1)) out.nbr.push_back(*it);
  }
  out.first.back() = static_cast<std::int32_t>(out.nbr.size());
  return out;
}

ImproveStats improve_mesh(Mesh<2>& m, const std::vector<std::uint8_t>& locked, const ImproveOptions& opt) {
  const int rounds = opt.rounds, n_threads = opt.n_threads;
  const SlideFn& slide = opt.slide;
  std::vector<std::uint8_t>* const at_rest = opt.at_rest;
  ImproveStats st;
  const std::size_t n_nodes = m.points.size();
  constexpr double unknown = std::numeric_limits<double>::quiet_NaN();
  // Each element's smallest angle as its largest corner cotangent (cot); the exact degrees
  // (element_min_angle) are computed, not kept, when a comparison needs them (rarely: a cache
  // was 8 bytes an element at this stage's memory); every decision below is the one the
  // degrees make (exceeds).
  std::vector<double> cot;
  reserve_huge(cot, m.solid.size(), n_threads);
  cot.resize(m.solid.size());
  for_each_range(m.solid.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) cot[e] = element_top_cot(m, e);
  });
  auto exact = [&](std::size_t e) { return element_min_angle(m, e); };
  // The exact degrees of elements as they stand (not at a trial position), remembered in a
  // direct-mapped table by element id and forgotten where cot changes: a node whose elements
  // tie in cotangent asks for all their degrees, and its neighbours, visited next, ask for
  // most of the same (flange level 9: most of the atan2 calls of this stage).
  // One per thread of the node sweep (core/partitioned_sweep.hpp: elements of two threads' nodes
  // are disjoint while a part runs; the tables are cleared where that ends). The flips use the
  // caller's, worker 0.
  auto exact_in = [&](Memo& memo, std::size_t e) {
    const std::size_t slot = e & (Memo::n - 1);
    if (memo.elem[slot] != static_cast<std::int32_t>(e)) {
      memo.deg[slot] = exact(e);
      memo.elem[slot] = static_cast<std::int32_t>(e);
    }
    return memo.deg[slot];
  };
  auto forget_in = [&](Memo& memo, std::int32_t e) {
    std::int32_t& held = memo.elem[static_cast<std::size_t>(e) & (Memo::n - 1)];
    if (held == e) held = -1;
  };
  // The smallest degrees over the mesh: only elements within rounding of the largest
  // cotangent (or without a finite one) can hold it.
  // (On threads: a max and a min, exact in any order.)
  auto mesh_min = [&] {
    const double top = range_max(cot.size(), n_threads, [&](std::size_t e) {
      return std::isfinite(cot[e]) ? cot[e] : -std::numeric_limits<double>::infinity();
    });
    const double band = 1e-12 * (1.0 + top * top);
    return std::min(180.0, range_min(cot.size(), n_threads, [&](std::size_t e) {
      return !std::isfinite(cot[e]) || !(top - cot[e] > band) ? exact(e) : 180.0;
    }));
  };
  if (opt.measure_min) st.min_angle_before = mesh_min();

  // Interface edges never flip (sorted keys, binary search).
  using EdgeKey = std::uint64_t;
  auto key_of = [](std::int32_t a, std::int32_t b) {
    return (static_cast<EdgeKey>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  std::vector<EdgeKey> interface_edge;
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    interface_edge.push_back(key_of(v[0].v, v[1].v));
  }
  std::sort(interface_edge.begin(), interface_edge.end());
  const InterfaceNeighbours curve_neighbours = interface_neighbours(m);

  // Flips are tried only on edges of elements below `good` degrees: the interior templates have
  // 45 degrees already, so flipping costs little beyond the boundary layer.
  const double good = 44.0, good_cot = 1.0 / std::tan(good * M_PI / 180.0);
  // A cotangent in [0, good_cot - 1e-6) is good without exceeds(): there its upper bound is
  // below -4e-7 (hi2 = good_cot^2), far past the slack, so exceeds() says false too. Most
  // triangles are (the candidate scan asks of every triangle in every flip pass).
  const double clearly_good_cot = good_cot - 1e-6;
  auto is_good = [&](Memo& memo, std::size_t e) {  // exact(e) >= good
    if (cot[e] >= 0.0 && cot[e] < clearly_good_cot) return true;
    return !exceeds(good_cot, [&] { return good; }, cot[e], [&] { return exact_in(memo, e); }, 0.0);
  };
  std::vector<EdgeKey> candidates, candidates_scratch;
  // The triangles that may be below `good`: a superset, kept instead of asking is_good of every
  // triangle in every flip pass (flange level 9: about 20 passes over 340,000 triangles). A
  // triangle joins when its cotangent is set to a value that is not clearly good (a flip, an
  // accepted move); a pass keeps only those still below `good`. The candidates are sorted, so
  // they are the same edges in the same order as from the scan of all triangles.
  std::vector<std::int32_t> unsure, unsure_scratch;
  auto maybe_bad_to = [&](std::vector<std::int32_t>& list, std::int32_t e) {
    const double c = cot[static_cast<std::size_t>(e)];
    if (m.solid.type[static_cast<std::size_t>(e)] == ElemType::Tri3 && !(c >= 0.0 && c < clearly_good_cot)) list.push_back(e);
  };
  for (std::size_t e = 0; e < m.solid.size(); ++e) maybe_bad_to(unsure, static_cast<std::int32_t>(e));
  LiveIncidence incident(m, n_threads);
  // A pass looks triangles up at the start's connectivity: its flips (e0, e1, a, b, c, d) update
  // the incidence after it (a flipped triangle is `touched` and skipped until then anyway).
  std::vector<std::array<std::int32_t, 6>> flipped;
  std::vector<std::uint8_t> touched(m.solid.size(), 0);
  // settled[v]: v's last guarded move was rejected and no node of its elements has moved nor
  // has any of its elements flipped since; its target, its elements' angles and the trial
  // angles would be the same numbers, so it would be rejected again and is skipped.
  // Free nodes the smoothing left at rest would be found within rounding by their first visit
  // (the same neighbours, the same sums, the same share), which gathers them from their
  // elements: most nodes of a mesh (NimbusSans U0067 at 10^6 triangles, one thread: this stage
  // 0.157-0.165 s -> 0.130-0.137 in alternating runs). at_rest's storage becomes settled's.
  std::vector<std::uint8_t> settled;
  if (at_rest && at_rest->size() == n_nodes) {
    settled = std::move(*at_rest);
    for (std::size_t v = 0; v < n_nodes; ++v) settled[v] = settled[v] == 1 && locked[v] == 0 ? 1 : 0;
  } else {
    settled.assign(n_nodes, 0);
  }
  if (at_rest) at_rest->clear();
  // The node sweep's working space, one per thread.
  struct alignas(64) Worker {
    Memo memo;
    std::vector<std::uint8_t> listed;  ///< w is among the neighbours being gathered
    std::vector<std::int32_t> nb, unsure;
    std::vector<double> trial_cot, trial_deg;
    std::size_t moves = 0;
  };
  // The nodes in slabs, cut once (the node sweep's order, core/partitioned_sweep.hpp).
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, default_sweep_parts, n_threads);
  // The separators of the first mesh; a flip whose four nodes lie in two parts or more makes
  // them all separators (so every element across parts has only separators: the parts' inner
  // nodes still share no element), instead of a pass over all elements after each round's
  // flips (2.4% of a flange run at 5.4 M triangles).
  std::vector<std::uint8_t> sep = separators(part, m.solid, n_threads);
  std::vector<Worker> workers(static_cast<std::size_t>(std::max(1, n_threads)));
  for (Worker& w : workers) w.listed.assign(n_nodes, 0);
  Memo& memo0 = workers[0].memo;
  // A flip pass's decision for each candidate edge: its triangles (e0 < e1) and nodes, and
  // the flipped triangles' largest cotangents; e0 = -1 for no flip.
  struct FlipPlan {
    std::array<std::int32_t, 6> flip{-1, -1, -1, -1, -1, -1};  ///< e0, e1, a, b, c, d
    double cot0 = 0.0, cot1 = 0.0;
  };
  std::vector<FlipPlan> plans;
  // Candidates a pass decided not to flip (sorted), and the nodes of that pass's flips: no node
  // moves between a round's flip passes, so the next pass would decide the same for such an edge
  // unless a flip rewrote one of its triangles, which then had both its ends among the flip's
  // four nodes. Those edges are not decided again (NimbusSans U0067 at 10^6 triangles, one
  // thread, three alternating rounds: this stage 0.124-0.132 s -> 0.115-0.124).
  std::vector<EdgeKey> kept_edges;
  std::vector<std::uint8_t> flip_node(n_nodes, 0), known;
  std::optional<PartitionedSweep> sweep;
  bool new_separators = false;
  for (int round = 0; round < rounds; ++round) {
    kept_edges.clear();  // (the sweep below moved nodes)
    // ---- flips: triangles only; repeat passes until none improves ----
    for (int pass = 0; pass < 8; ++pass) {
      candidates.clear();
      radix_sort_lsd(unsure, unsure_scratch);
      unsure.erase(std::unique(unsure.begin(), unsure.end()), unsure.end());
      std::size_t n_unsure = 0;
      for (const std::int32_t e : unsure) {
        if (is_good(memo0, static_cast<std::size_t>(e))) continue;
        unsure[n_unsure++] = e;
        const VertexId* v = m.solid.nodes(ElemId{e});
        for (int k = 0; k < 3; ++k) candidates.push_back(key_of(v[k].v, v[(k + 1) % 3].v));
      }
      unsure.resize(n_unsure);
      if (candidates.empty()) break;
      radix_sort_lsd(candidates, candidates_scratch);
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      // Connectivity as at the start of the pass: a flipped triangle is `touched` and its edges
      // are skipped for the rest of the pass. Every candidate's flip is decided on the pass's
      // start state, on n_threads threads, then the flips are made in candidate order, skipping
      // a candidate whose triangles an earlier flip touched: the serial loop's flips. (A flip
      // moves no node and changes only its two triangles; an edge it makes or rewires is one
      // of theirs, and the serial loop skips those too, by `touched` or by finding not two
      // triangles on the edge. The decisions were all on the caller's thread: 36 of this stage's
      // 145 ms at flange 1e6, on one thread or two.)
      // The last pass's flips (still in `flipped`) mark their nodes while the kept edges are
      // matched.
      known.assign(candidates.size(), 0);
      for (const auto& f : flipped)
        for (int k = 2; k < 6; ++k) flip_node[static_cast<std::size_t>(f[k])] = 1;
      for (std::size_t i = 0, j = 0; i < candidates.size() && j < kept_edges.size(); ++i) {
        while (j < kept_edges.size() && kept_edges[j] < candidates[i]) ++j;
        if (j == kept_edges.size() || kept_edges[j] != candidates[i]) continue;
        known[i] = !flip_node[candidates[i] >> 32] || !flip_node[candidates[i] & 0xffffffffu];
      }
      for (const auto& f : flipped)
        for (int k = 2; k < 6; ++k) flip_node[static_cast<std::size_t>(f[k])] = 0;
      flipped.clear();  // (touched is all 0 here: the last pass cleared what it set)
      plans.assign(candidates.size(), FlipPlan{});
      std::atomic<std::size_t> next_memo{0};
      for_each_range(candidates.size(), n_threads, [&](std::size_t i0, std::size_t i1) {
        Memo& memo = workers[next_memo++].memo;  // a cache: any thread's, one thread at a time
        for (std::size_t i = i0; i < i1; ++i) {
          if (known[i]) continue;  // no flip, as the last pass decided
          const EdgeKey key = candidates[i];
          const auto lo = static_cast<std::int32_t>(key >> 32), hi = static_cast<std::int32_t>(key & 0xffffffffu);
          std::int32_t pair[2];
          int n_pair = 0;
          for (const std::int32_t e : incident.of(lo)) {
            if (m.solid.type[static_cast<std::size_t>(e)] != ElemType::Tri3) continue;
            if (local_edge(m.solid.nodes(ElemId{e}), lo, hi) < 0) continue;
            if (n_pair < 2) pair[n_pair] = e;
            ++n_pair;
          }
          if (n_pair != 2) continue;  // a boundary edge, or (never in a valid mesh) an edge of 3+ triangles
          const std::int32_t e0 = std::min(pair[0], pair[1]), e1 = std::max(pair[0], pair[1]);
          if (is_good(memo, static_cast<std::size_t>(e0)) && is_good(memo, static_cast<std::size_t>(e1))) continue;
          if (std::binary_search(interface_edge.begin(), interface_edge.end(), key)) continue;
          const VertexId* v0 = m.solid.nodes(ElemId{e0});
          const VertexId* v1 = m.solid.nodes(ElemId{e1});
          const int k0 = local_edge(v0, lo, hi), k1 = local_edge(v1, lo, hi);
          // Triangle 0 = (a, b, c) with edge a-b at k0; triangle 1 = (b, a, d).
          const std::int32_t a = v0[k0].v, b = v0[(k0 + 1) % 3].v, c = v0[(k0 + 2) % 3].v;
          const std::int32_t d = v1[(k1 + 2) % 3].v;
          if (v1[k1].v != b || v1[(k1 + 1) % 3].v != a) continue;  // not opposite orientation
          const P2 &pa = m.points[a], &pb = m.points[b], &pc = m.points[c], &pd = m.points[d];
          // before = min(t[0], t[1]) now, after = min(t[2], t[3]) flipped; flip iff
          // after > before + 1e-9, i.e. each of t[2], t[3] exceeds t[0] or t[1] by 1e-9.
          const std::array<std::array<P2, 3>, 4> t = {{{pa, pb, pc}, {pb, pa, pd}, {pc, pa, pd}, {pd, pb, pc}}};
          std::array<double, 4> tc, td;
          // t[0] and t[1] are e0 and e1 with their nodes rotated: the same corners, so the same
          // largest cotangent as the cached one when that is finite (no corner returned early).
          for (int j = 0; j < 4; ++j) {
            const double cached = j < 2 ? cot[j == 0 ? e0 : e1] : unknown;
            tc[j] = std::isfinite(cached) ? cached : polygon_top_cot<3>(t[j].data());
            td[j] = unknown;
          }
          auto tri_deg = [&](int j) {
            if (std::isnan(td[j])) td[j] = polygon_min_angle_n<3>(t[j].data());
            return td[j];
          };
          auto beats = [&](int x, int y) { return exceeds(tc[x], [&] { return tri_deg(x); }, tc[y], [&] { return tri_deg(y); }, 1e-9); };
          if (!((beats(2, 0) || beats(2, 1)) && (beats(3, 0) || beats(3, 1)))) continue;
          plans[i] = FlipPlan{{e0, e1, a, b, c, d}, tc[2], tc[3]};
        }
      });
      std::size_t flips = 0;
      for (const FlipPlan& plan : plans) {
        const auto [e0, e1, a, b, c, d] = plan.flip;
        if (e0 < 0 || touched[e0] || touched[e1]) continue;
        // New triangles (c, a, d) and (d, b, c): both positive since after > before >= -1.
        VertexId* v0 = m.solid.node.data() + m.solid.offset[e0];
        VertexId* v1 = m.solid.node.data() + m.solid.offset[e1];
        v0[0] = VertexId{c}, v0[1] = VertexId{a}, v0[2] = VertexId{d};
        v1[0] = VertexId{d}, v1[1] = VertexId{b}, v1[2] = VertexId{c};
        touched[e0] = touched[e1] = 1;
        settled[a] = settled[b] = settled[c] = settled[d] = 0;
        cot[e0] = plan.cot0;
        cot[e1] = plan.cot1;
        maybe_bad_to(unsure, e0), maybe_bad_to(unsure, e1);
        for (Worker& w : workers) forget_in(w.memo, e0), forget_in(w.memo, e1);
        flipped.push_back(plan.flip);
        if (spans_parts(part, a, b, c, d) && !(sep[a] && sep[b] && sep[c] && sep[d])) {
          sep[a] = sep[b] = sep[c] = sep[d] = 1;
          new_separators = true;
        }
        ++flips;
      }
      // Only the flipped triangles were touched: clearing them, not the whole array (a pass
      // over every element, up to 8 passes a round).
      for (const auto& f : flipped) touched[static_cast<std::size_t>(f[0])] = touched[static_cast<std::size_t>(f[1])] = 0;
      // This pass's edges without a flip, for the next pass.
      kept_edges.clear();
      for (std::size_t i = 0; i < candidates.size(); ++i)
        if (plans[i].flip[0] < 0) kept_edges.push_back(candidates[i]);
      // (c, a, d) lost b and gained d; (d, b, c) lost a and gained c.
      for (const auto& [e0, e1, a, b, c, d] : flipped) {
        incident.remove(b, e0), incident.remove(a, e1);
        incident.add(d, e0), incident.add(c, e1);
      }
      st.flips += flips;
      if (flips == 0) break;
    }

    // ---- guarded smoothing on the smallest angle ----
    // In slabs on threads (core/partitioned_sweep.hpp): a visit reads and writes only v, its
    // elements' cotangents and (marks) the settled flags of their nodes.
    // (The order changes only where a flip made separators.)
    if (new_separators || !sweep) {
      const auto is_swept = [&](std::int32_t v) { return !locked[v] || (locked[v] == 2 && slide); };
      sweep.emplace(part, default_sweep_parts, sep, is_swept, n_threads);
      new_separators = false;
    }
    sweep->run([&](std::int32_t vi, int thread) {
      Worker& my = workers[static_cast<std::size_t>(thread)];
      const auto v = static_cast<std::size_t>(vi);
      std::vector<std::int32_t>& nb = my.nb;
      const bool sliding = locked[v] == 2 && slide;
      if (settled[v]) return;
      const auto elems = incident.of(static_cast<std::int32_t>(v));
      if (elems.empty()) return;
      if (sliding) {
        nb.assign(curve_neighbours.of(v).begin(), curve_neighbours.of(v).end());
      } else {
        // The distinct edge neighbours, ascending (the centroid below sums them in that order).
        nb.clear();
        append_polygon_neighbours(m.solid, static_cast<std::int32_t>(v), elems, nb, my.listed);
      }
      if (nb.empty()) return;
      P2 target = P2::Zero();
      for (std::int32_t w : nb) target += m.points[w];
      target /= static_cast<double>(nb.size());
      if (within_rounding<2>(m.points, static_cast<std::int32_t>(v), nb, target, quality_rounding_share)) {
        settled[v] = 1;  // the same numbers until a node of its elements moves
        return;
      }
      // old_q, the smallest angle of v's elements, by cotangent: elems[worst] holds it. Its
      // exact degrees are computed only if a comparison needs them, as the smallest over all
      // of v's elements when another one is within rounding of it (a tie: the degrees may
      // order them otherwise) or one has no finite cotangent (then old_cot is NaN: exact only).
      std::size_t worst = 0;
      bool all_finite = std::isfinite(cot[elems[0]]);
      for (std::size_t k = 1; k < elems.size(); ++k) {
        all_finite = all_finite && std::isfinite(cot[elems[k]]);
        if (cot[elems[k]] > cot[elems[worst]]) worst = k;
      }
      const double old_cot = all_finite ? cot[elems[worst]] : unknown;
      bool tie = false;
      if (all_finite) {
        const double band = 2e-12 * (1.0 + old_cot * old_cot);
        for (std::size_t k = 0; k < elems.size() && !tie; ++k) tie = k != worst && !(old_cot - cot[elems[k]] > band);
      }
      double old_deg = unknown;
      const P2 saved = m.points[v];
      auto old_exact = [&] {
        if (std::isnan(old_deg)) {
          const P2 tried = m.points[v];
          m.points[v] = saved;
          if (tie || !all_finite) {
            old_deg = 180.0;
            for (const std::int32_t e : elems) old_deg = std::min(old_deg, exact_in(my.memo, static_cast<std::size_t>(e)));
          } else {
            old_deg = exact_in(my.memo, static_cast<std::size_t>(elems[worst]));
          }
          m.points[v] = tried;
        }
        return old_deg;
      };
      bool moved = false;
      std::vector<double>& trial_cot = my.trial_cot;
      std::vector<double>& trial_deg = my.trial_deg;
      trial_cot.resize(elems.size());
      trial_deg.resize(elems.size());
      for (double step : {1.0, 0.5, 0.25}) {
        m.points[v] = saved + step * (target - saved);
        if (sliding) m.points[v] = slide(static_cast<std::int32_t>(v), m.points[v]);
        if (m.points[v] == saved) break;
        // Accepted iff every incident element's angle exceeds old_q + 1e-12. The first one
        // that does not rejects the step and the others need not be evaluated; the element
        // that held old_q is the likeliest to fail, so it goes first.
        bool better = true;
        for (std::size_t j = 0; j < elems.size() && better; ++j) {
          const std::size_t k = worst_first(j, worst);
          const auto e = static_cast<std::size_t>(elems[k]);
          trial_cot[k] = element_top_cot(m, e);
          trial_deg[k] = unknown;
          auto trial_exact = [&] {
            if (std::isnan(trial_deg[k])) trial_deg[k] = element_min_angle(m, e);
            return trial_deg[k];
          };
          better = exceeds(trial_cot[k], trial_exact, old_cot, old_exact, 1e-12);
        }
        if (better) {
          moved = true;
          break;
        }
      }
      if (moved) {
        ++my.moves;
        for (std::size_t k = 0; k < elems.size(); ++k) {
          cot[elems[k]] = trial_cot[k];  // the accepted trial's
          maybe_bad_to(my.unsure, elems[k]);
          forget_in(my.memo, elems[k]);
          const ElemId id{elems[k]};
          const VertexId* ev = m.solid.nodes(id);
          for (int j = 0; j < m.solid.n_nodes_of(id); ++j) mark(settled[ev[j].v], 0);
        }
      } else {
        m.points[v] = saved;
        settled[v] = 1;
      }
    },
    [&] { for (Worker& w : workers) w.memo.clear(); },
    [&](std::int32_t v) { return settled[v] != 0; });
    for (Worker& w : workers) {
      w.memo.clear();
      st.moves += std::exchange(w.moves, 0);
      unsure.insert(unsure.end(), w.unsure.begin(), w.unsure.end());
      w.unsure.clear();
    }
  }
  if (opt.measure_min) st.min_angle_after = mesh_min();
  return st;
}

// The plain algorithm: every angle recomputed, half-edges sorted every pass.
ImproveStats improve_mesh_ref(Mesh<2>& m, const std::vector<std::uint8_t>& locked, int rounds, const SlideFn& slide) {
  ImproveStats st;
  auto mesh_min = [&] {
    double q = 180.0;
    for (std::size_t e = 0; e < m.solid.size(); ++e) q = std::min(q, min_corner_angle_deg(m, e));
    return q;
  };
  st.min_angle_before = mesh_min();
  const std::size_t n_nodes = m.points.size();

  // Interface edges never flip (sorted keys, binary search).
  using EdgeKey = std::uint64_t;
  auto key_of = [](std::int32_t a, std::int32_t b) {
    return (static_cast<EdgeKey>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  std::vector<EdgeKey> interface_edge;
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    interface_edge.push_back(key_of(v[0].v, v[1].v));
  }
  std::sort(interface_edge.begin(), interface_edge.end());

  // Flips are tried only on edges of elements below `good` degrees: the interior templates have
  // 45 degrees already, so flipping costs little beyond the boundary layer.
  const double good = 44.0;
  std::vector<double> angle(m.solid.size());
  struct HalfEdge {
    EdgeKey key;
    std::int32_t elem;
    int local;
  };
  std::vector<HalfEdge> half;
  // The node sweep's order: improve_mesh's (slabs cut once, separators after each round's flips).
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, default_sweep_parts, 1);
  std::vector<std::uint8_t> sep = separators(part, m.solid, 1);  // and the nodes of flips across parts
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t e = 0; e < m.solid.size(); ++e) angle[e] = min_corner_angle_deg(m, e);
    // ---- flips: triangles only; repeat passes until none improves ----
    for (int pass = 0; pass < 8; ++pass) {
      half.clear();
      for (std::size_t e = 0; e < m.solid.size(); ++e) {
        if (m.solid.type[e] != ElemType::Tri3) continue;
        const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
        for (int k = 0; k < 3; ++k)
          half.push_back({key_of(v[k].v, v[(k + 1) % 3].v), static_cast<std::int32_t>(e), k});
      }
      std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return x.key != y.key ? x.key < y.key : x.elem < y.elem;
      });
      std::vector<std::uint8_t> touched(m.solid.size(), 0);
      std::size_t flips = 0;
      for (std::size_t h = 0; h + 1 < half.size(); ++h) {
        if (half[h].key != half[h + 1].key || (h > 0 && half[h - 1].key == half[h].key) ||
            (h + 2 < half.size() && half[h + 2].key == half[h].key))
          continue;  // a boundary edge, or (never in a valid mesh) an edge of 3+ triangles
        const std::int32_t e0 = half[h].elem, e1 = half[h + 1].elem;
        const int k0 = half[h].local, k1 = half[h + 1].local;
        if (angle[e0] >= good && angle[e1] >= good) continue;
        if (std::binary_search(interface_edge.begin(), interface_edge.end(), half[h].key)) continue;
        if (touched[e0] || touched[e1]) continue;
        VertexId* v0 = m.solid.node.data() + m.solid.offset[e0];
        VertexId* v1 = m.solid.node.data() + m.solid.offset[e1];
        // Triangle 0 = (a, b, c) with edge a-b at k0; triangle 1 = (b, a, d).
        const std::int32_t a = v0[k0].v, b = v0[(k0 + 1) % 3].v, c = v0[(k0 + 2) % 3].v;
        const std::int32_t d = v1[(k1 + 2) % 3].v;
        if (v1[k1].v != b || v1[(k1 + 1) % 3].v != a) continue;  // not opposite orientation
        const P2 &pa = m.points[a], &pb = m.points[b], &pc = m.points[c], &pd = m.points[d];
        const double before = std::min(tri_min_angle(pa, pb, pc), tri_min_angle(pb, pa, pd));
        const double after = std::min(tri_min_angle(pc, pa, pd), tri_min_angle(pd, pb, pc));
        if (after <= before + 1e-9) continue;
        // New triangles (c, a, d) and (d, b, c): both positive since after > before >= -1.
        v0[0] = VertexId{c}, v0[1] = VertexId{a}, v0[2] = VertexId{d};
        v1[0] = VertexId{d}, v1[1] = VertexId{b}, v1[2] = VertexId{c};
        if (spans_parts(part, a, b, c, d)) sep[a] = sep[b] = sep[c] = sep[d] = 1;
        touched[e0] = touched[e1] = 1;
        angle[e0] = tri_min_angle(pc, pa, pd);
        angle[e1] = tri_min_angle(pd, pb, pc);
        ++flips;
      }
      st.flips += flips;
      if (flips == 0) break;
    }

    // ---- guarded smoothing on the smallest angle ----
    std::vector<std::vector<std::int32_t>> incident(n_nodes), neighbours(n_nodes), curve_neighbours(n_nodes);
    for (std::size_t e = 0; e < m.interface.size(); ++e) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
      curve_neighbours[v[0].v].push_back(v[1].v);
      curve_neighbours[v[1].v].push_back(v[0].v);
    }
    for (std::size_t e = 0; e < m.solid.size(); ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = m.solid.n_nodes_of(id);
      const VertexId* v = m.solid.nodes(id);
      for (int k = 0; k < n; ++k) {
        incident[v[k].v].push_back(static_cast<std::int32_t>(e));
        neighbours[v[k].v].push_back(v[(k + 1) % n].v);
        neighbours[v[k].v].push_back(v[(k + n - 1) % n].v);
      }
    }
    const PartitionedSweep sweep(part, default_sweep_parts, sep, [](std::int32_t) { return true; }, 1);
    for (const std::int32_t vi : sweep.order()) {
      const auto v = static_cast<std::size_t>(vi);
      const bool sliding = locked[v] == 2 && slide;
      if ((locked[v] && !sliding) || incident[v].empty()) continue;
      auto& nb = sliding ? curve_neighbours[v] : neighbours[v];
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
      if (nb.empty()) continue;
      P2 target = P2::Zero();
      for (std::int32_t w : nb) target += m.points[w];
      target /= static_cast<double>(nb.size());
      if (within_rounding<2>(m.points, static_cast<std::int32_t>(v), nb, target, quality_rounding_share)) continue;
      auto local_min = [&] {
        double q = 180.0;
        for (std::int32_t e : incident[v]) q = std::min(q, min_corner_angle_deg(m, e));
        return q;
      };
      const double old_q = local_min();
      const P2 saved = m.points[v];
      bool moved = false;
      for (double step : {1.0, 0.5, 0.25}) {
        m.points[v] = saved + step * (target - saved);
        if (sliding) m.points[v] = slide(static_cast<std::int32_t>(v), m.points[v]);
        if (m.points[v] == saved) break;
        if (local_min() > old_q + 1e-12) {
          moved = true;
          break;
        }
      }
      if (moved) {
        ++st.moves;
      } else {
        m.points[v] = saved;
      }
    }
  }
  st.min_angle_after = mesh_min();
  return st;
}

}  // namespace febemesh::dim2
