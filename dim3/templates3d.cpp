#include "dim3/templates3d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "core/cube_faces.hpp"
#include "core/error.hpp"
#include "core/fnv_lanes.hpp"
#include "core/huge_pages.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh::dim3 {
namespace {

using LP = LatticePoint<3>;
using Tri = std::array<std::int32_t, 3>;

LP midpoint(const LP& a, const LP& b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }

/// Removes cyclically repeated consecutive ids.
std::vector<std::int32_t> dedupe_ring(const std::vector<std::int32_t>& r) {
  std::vector<std::int32_t> out;
  for (std::int32_t v : r)
    if (out.empty() || out.back() != v) out.push_back(v);
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  return out;
}

/// The ring without its spikes (a b a -> a, cyclically) and repeated nodes: the polygon of the
/// projections where two corners that are not neighbours land on the same surface point and the
/// corner between them elsewhere (the spike encloses no area).
std::vector<std::int32_t> despike_ring(std::vector<std::int32_t> r) {
  r = dedupe_ring(r);
  for (bool changed = true; changed && r.size() >= 3;) {
    changed = false;
    for (std::size_t i = 0; i < r.size() && r.size() >= 3; ++i) {
      const std::size_t prev = (i + r.size() - 1) % r.size(), next = (i + 1) % r.size();
      if (r[prev] != r[next]) continue;
      // prev, i, next = a b a: drop b and the second a.
      const std::size_t lo = std::min(i, next), hi = std::max(i, next);
      r.erase(r.begin() + static_cast<std::ptrdiff_t>(hi));
      r.erase(r.begin() + static_cast<std::ptrdiff_t>(lo));
      r = dedupe_ring(r);
      changed = true;
      break;
    }
  }
  return r.size() >= 3 ? r : std::vector<std::int32_t>{};
}

/// Removes every triangle whose reverse is also in `tris` (a fin: two faces of one cell back
/// to back, enclosing nothing). Its two cones would have opposite volumes, one of them inverted,
/// and no node move can fix that. Such a fin appears where a face corner's neighbours on both
/// sides project to one surface point and the corner itself elsewhere (measured:
/// regressions/voxel-notched-cube-fin.off at the notch's concave corner). Without it the cell
/// pinches there and the two cells beside it meet through the triangle.
std::size_t cancel_fins(std::vector<Tri>& tris) {
  const auto canonical = [](Tri t) {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    return t;
  };
  std::vector<std::uint8_t> gone(tris.size(), 0);
  std::size_t n = 0;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    if (gone[i]) continue;
    const Tri rev = canonical({tris[i][0], tris[i][2], tris[i][1]});
    for (std::size_t j = i + 1; j < tris.size(); ++j)
      if (!gone[j] && canonical(tris[j]) == rev) {
        gone[i] = gone[j] = 1;
        ++n;
        break;
      }
  }
  if (n == 0) return 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < tris.size(); ++i)
    if (!gone[i]) tris[k++] = tris[i];
  tris.resize(k);
  return n;
}

/// Smallest angle of triangle abc (radians, 0 when degenerate).
double min_angle(const P3& a, const P3& b, const P3& c) {
  const auto ang = [](const P3& o, const P3& u, const P3& v) {
    const P3 x = u - o, y = v - o;
    const double n = x.norm() * y.norm();
    if (n <= 0) return 0.0;
    return std::atan2(x.cross(y).norm(), x.dot(y));
  };
  return std::min({ang(a, b, c), ang(b, c, a), ang(c, a, b)});
}

/// A hash of the first n tetrahedra's node ids, levels and cells (InteriorTets::hash).
std::uint64_t interior_hash(const Mesh<3>& m, const std::vector<std::int32_t>& cell, std::size_t n) {
  FnvLanes h;
  for (std::size_t i = 0; i < 4 * n; ++i) h.add(static_cast<std::uint32_t>(m.solid.node[i].v));
  for (std::size_t e = 0; e < n; ++e) h.add(static_cast<std::uint64_t>(m.level[e]) << 32 | static_cast<std::uint32_t>(cell[e]));
  return h.value();
}

struct Builder {
  const Orthtree<3>& tree;
  const OctantComplex& oc;
  const SurfacePointFn& surface_point;
  TetMesh out;
  std::map<std::uint64_t, std::int32_t> fan;  // fan centre nodes by lattice point key
  /// Morton keys of oc.lattice.points (ascending, as the points are), and an open-addressing
  /// hash table of their indices (linear probing, at most half full; -1 empty): lattice_node's
  /// lookups, two or three per square edge, were a binary search over all nodes (150 M
  /// instructions at sphere966 L5). Indices only (4 B a slot, 8-16 B a node): slots with the
  /// keys in them took up to 64 B a node.
  std::vector<std::uint64_t> keys;
  std::vector<std::int32_t> table;
  int table_bits = 1;

  std::size_t home(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - table_bits));
  }
  void index_lattice() {
    keys.reserve(oc.lattice.points.size());
    for (const LP& p : oc.lattice.points) keys.push_back(point_key<3>(p));
    while ((std::size_t{1} << table_bits) < 2 * keys.size() + 2) ++table_bits;
    table.assign(std::size_t{1} << table_bits, -1);
    const std::size_t mask = table.size() - 1;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      std::size_t h = home(keys[i]);
      while (table[h] >= 0) h = (h + 1) & mask;
      table[h] = static_cast<std::int32_t>(i);
    }
  }

  std::int32_t add_point(const P3& p, const BoundaryLocation& w = {}) {
    out.mesh.add_point(p);
    out.where.push_back(w);
    return static_cast<std::int32_t>(out.mesh.points.size() - 1);
  }
  /// oc.lattice.find(p): the node's index, -1 if p is not a lattice node.
  std::int32_t lattice_node(const LP& p) const {
    const std::uint64_t key = point_key<3>(p);
    const std::size_t mask = table.size() - 1;
    for (std::size_t h = home(key);; h = (h + 1) & mask) {
      const std::int32_t i = table[h];
      if (i < 0 || keys[static_cast<std::size_t>(i)] == key) return i;
    }
  }
  std::int32_t fan_node(const LP& p) {
    const std::uint64_t key = point_key<3>(p);
    const auto it = fan.find(key);
    if (it != fan.end()) return it->second;
    const std::int32_t id = add_point(position(tree, p));
    fan.emplace(key, id);
    return id;
  }
  void square(const std::array<LP, 4>& q, std::uint32_t len, std::vector<Tri>& tris) {
    triangulate_square(
        q, len, [&](const LP& p) { return lattice_node(p); }, [&](const LP& p) { return fan_node(p); }, tris);
  }
  /// Cones from a new centroid node at `centre` over the outward triangles.
  void cones(const std::vector<Tri>& tris, const P3& centre, std::uint8_t level, bool boundary, std::int32_t cell) {
    const VertexId x{add_point(centre)};
    for (const Tri& t : tris) {
      if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
        ++out.n_dropped_degenerate;
        continue;
      }
      out.mesh.solid.add(ElemType::Tet4, {VertexId{t[0]}, VertexId{t[2]}, VertexId{t[1]}, x});
      out.mesh.level.push_back(level);
      out.mesh.from_boundary_cell.push_back(boundary ? 1 : 0);
      out.cell.push_back(cell);
    }
  }
  const P3& at(std::int32_t v) const { return out.mesh.points[v]; }
};

}  // namespace

void triangulate_quad_by_id(std::array<std::int32_t, 4> q, std::vector<Tri>& out) {
  // dedupe_ring in place (no heap vector: once per square, 54 M instructions at sphere966 L5).
  std::array<std::int32_t, 4> r;
  int n = 0;
  for (std::int32_t v : q)
    if (n == 0 || r[n - 1] != v) r[n++] = v;
  while (n > 1 && r[n - 1] == r[0]) --n;
  if (n < 3) return;
  if (n == 3) {
    out.push_back({r[0], r[1], r[2]});
    return;
  }
  const int m = static_cast<int>(std::min_element(r.begin(), r.end()) - r.begin());
  if (m % 2 == 0) {
    out.push_back({r[0], r[1], r[2]});
    out.push_back({r[0], r[2], r[3]});
  } else {
    out.push_back({r[1], r[2], r[3]});
    out.push_back({r[1], r[3], r[0]});
  }
}

void triangulate_square(const std::array<LP, 4>& q, std::uint32_t len,
                        const std::function<std::int32_t(const LP&)>& lattice_node,
                        const std::function<std::int32_t(const LP&)>& fan_node, std::vector<Tri>& out) {
  if (len >= 2) {
    const LP x = midpoint(q[0], q[2]);
    if (lattice_node(x) >= 0) {
      // Finer octants on the other side: the four sub-squares, each counter-clockwise.
      const LP m01 = midpoint(q[0], q[1]), m12 = midpoint(q[1], q[2]), m23 = midpoint(q[2], q[3]),
               m30 = midpoint(q[3], q[0]);
      const std::uint32_t h = len / 2;
      triangulate_square({q[0], m01, x, m30}, h, lattice_node, fan_node, out);
      triangulate_square({m01, q[1], m12, x}, h, lattice_node, fan_node, out);
      triangulate_square({x, m12, q[2], m23}, h, lattice_node, fan_node, out);
      triangulate_square({m30, x, m23, q[3]}, h, lattice_node, fan_node, out);
      return;
    }
  }
  std::array<std::int32_t, 8> ring;  // corners and edge midpoints: no heap vector per square
  std::size_t n_ring = 0;
  for (int k = 0; k < 4; ++k) {
    ring[n_ring++] = lattice_node(q[k]);
    MESH_ASSERT(ring[n_ring - 1] >= 0, "square corner is not a lattice node");
    if (len >= 2) {
      const std::int32_t m = lattice_node(midpoint(q[k], q[(k + 1) % 4]));
      if (m >= 0) ring[n_ring++] = m;
    }
  }
  if (n_ring == 4) {
    triangulate_quad_by_id({ring[0], ring[1], ring[2], ring[3]}, out);
    return;
  }
  const std::int32_t c = fan_node(midpoint(q[0], q[2]));
  for (std::size_t k = 0; k < n_ring; ++k) out.push_back({c, ring[k], ring[(k + 1) % n_ring]});
}

TetMesh tetrahedralize(const Orthtree<3>& t, const OctantComplex& oc, const SurfacePointFn& surface_point, int n_threads,
                       InteriorTets* kept, const TetMesh* last) {
  Builder b{t, oc, surface_point, {}, {}, {}, {}};
  b.index_lattice();
  b.out.mesh.points = oc.points;
  b.out.where = oc.where;
  std::vector<Tri> tris;

  // Interior octants, in three passes, so that the nodes and tetrahedra come out in the order
  // (and with the ids) of one pass over the octants whatever the thread count:
  // 1. on n_threads ranges: each octant's face triangles, with its fan centres as -1 - (their
  //    index among the octant's own fan centres) instead of node ids;
  // 2. in order: the fan centre nodes (first use creates one, as fan_node does) and the
  //    centroid node of each octant, and where its tetrahedra start;
  // 3. on the same ranges: the tetrahedra, written where they go.
  const std::size_t n_int = oc.interior.size();
  struct Range {
    std::size_t begin = 0, end = 0;
    std::vector<Tri> tris;
    std::vector<LP> fans;                 // the octants' fan centres, octant by octant
    std::vector<std::int32_t> fan_ids;    // their node ids (pass 2)
  };
  // With `kept` filled for this tree and `last` beginning with its tetrahedra: the interior
  // part from there (passes 1-3 skipped).
  const bool reuse = kept && kept->filled && kept->n_complex_points == oc.points.size() && kept->n_interior == n_int &&
                     last && last->mesh.solid.size() >= kept->n_tets && last->mesh.level.size() >= kept->n_tets &&
                     last->cell.size() >= kept->n_tets && interior_hash(last->mesh, last->cell, kept->n_tets) == kept->hash;
  std::vector<std::uint16_t> n_tris, n_fans, n_tets;
  std::vector<Range> ranges;
  std::vector<std::int32_t> centroid;
  std::vector<std::size_t> tet_start;
  if (reuse) {
    // The nodes as pass 2 makes them (add_point of the same positions).
    for (const std::uint64_t o : kept->origin)
      b.add_point((o & InteriorTets::centroid_tag) ? geometry(t, t.leaf(oc.interior[o & ~InteriorTets::centroid_tag])).center()
                                                   : position(t, point_from_key<3>(o)));
    b.fan = std::map<std::uint64_t, std::int32_t>(kept->fan.begin(), kept->fan.end());
    b.out.n_dropped_degenerate = kept->n_dropped_degenerate;
  } else {
    if (kept) kept->filled = false, kept->origin.clear();
    n_tris.resize(n_int), n_fans.resize(n_int), n_tets.resize(n_int);
    std::mutex ranges_mutex;
    for_each_range(n_int, n_threads, [&](std::size_t begin, std::size_t end) {
      Range r;
      r.begin = begin, r.end = end;
      // 12 face triangles an octant without hanging nodes, more with: room for 14 a octant, so
      // that the list seldom grows by doubling (each growth a fresh copy, faulted in page by page).
      reserve_room(r.tris, 14 * (end - begin));
      std::vector<Tri> cell_tris;
      std::vector<LP> cell_fans;
      const auto fan_placeholder = [&](const LP& p) {
        const auto it = std::find(cell_fans.begin(), cell_fans.end(), p);
        if (it != cell_fans.end()) return -1 - static_cast<std::int32_t>(it - cell_fans.begin());
        cell_fans.push_back(p);
        return -static_cast<std::int32_t>(cell_fans.size());
      };
      const auto lattice_node = [&](const LP& p) { return b.lattice_node(p); };
      for (std::size_t k = begin; k < end; ++k) {
        const Cell<3>& c = t.leaf(oc.interior[k]);
        cell_tris.clear();
        cell_fans.clear();
        for (int f = 0; f < Cube<3>::n_faces; ++f) {
          const auto& fc = FaceCorners<3>::corners[f];
          triangulate_square({corner(c, fc[0]), corner(c, fc[1]), corner(c, fc[2]), corner(c, fc[3])}, length(c), lattice_node,
                             fan_placeholder, cell_tris);
        }
        MESH_ASSERT(cell_tris.size() < 65536, "too many face triangles in one octant");
        n_tris[k] = static_cast<std::uint16_t>(cell_tris.size());
        n_fans[k] = static_cast<std::uint16_t>(cell_fans.size());
        std::uint16_t good = 0;
        for (const Tri& q : cell_tris) good += (q[0] != q[1] && q[1] != q[2] && q[2] != q[0]) ? 1 : 0;
        n_tets[k] = good;
        r.tris.insert(r.tris.end(), cell_tris.begin(), cell_tris.end());
        r.fans.insert(r.fans.end(), cell_fans.begin(), cell_fans.end());
      }
      const std::lock_guard<std::mutex> lock(ranges_mutex);
      ranges.push_back(std::move(r));
    });
    std::sort(ranges.begin(), ranges.end(), [](const Range& x, const Range& y) { return x.begin < y.begin; });
    centroid.resize(n_int);
    tet_start.assign(n_int + 1, 0);
    for (Range& r : ranges) {
      r.fan_ids.resize(r.fans.size());
      std::size_t fan = 0;
      for (std::size_t k = r.begin; k < r.end; ++k) {
        for (std::size_t i = 0; i < n_fans[k]; ++i, ++fan) {
          const std::size_t n_before = b.out.mesh.points.size();
          r.fan_ids[fan] = b.fan_node(r.fans[fan]);
          if (kept && b.out.mesh.points.size() > n_before) kept->origin.push_back(point_key<3>(r.fans[fan]));
        }
        centroid[k] = b.add_point(geometry(t, t.leaf(oc.interior[k])).center());
        if (kept) kept->origin.push_back(InteriorTets::centroid_tag | k);
        tet_start[k + 1] = tet_start[k] + n_tets[k];
        b.out.n_dropped_degenerate += n_tris[k] - n_tets[k];
      }
    }
  }
  const std::size_t n_int_tets = reuse ? kept->n_tets : tet_start[n_int];
  if (kept && !reuse) {
    kept->fan.assign(b.fan.begin(), b.fan.end());
    kept->n_dropped_degenerate = b.out.n_dropped_degenerate;
  }
  Mesh<3>& m = b.out.mesh;

  // Boundary octants.
  const std::int32_t n_interior = static_cast<std::int32_t>(oc.interior.size());
  for (std::size_t k = 0; k < oc.boundary.size(); ++k) {
    const BoundaryOctant& bo = oc.boundary[k];
    const std::size_t n = bo.ring.size();
    std::vector<std::int32_t> p(n);
    for (std::size_t i = 0; i < n; ++i) {
      p[i] = oc.projection[bo.ring[i]];
      MESH_ASSERT(p[i] >= 0, "boundary octant node without projection");
    }
    tris.clear();
    // Face side: the square as seen from the interior octant, reversed.
    const auto& fc = FaceCorners<3>::corners[bo.face];
    std::vector<Tri> qtris;
    b.square({corner(bo.cell, fc[0]), corner(bo.cell, fc[1]), corner(bo.cell, fc[2]), corner(bo.cell, fc[3])},
             length(bo.cell), qtris);
    for (const Tri& q : qtris) tris.push_back({q[0], q[2], q[1]});
    // Sides Qi Qj Pj Pi, one per ring edge (split at hanging midpoints).
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      triangulate_quad_by_id({bo.ring[i], bo.ring[j], p[j], p[i]}, tris);
    }
    // Surface face: owned by this cell alone.
    const std::vector<std::int32_t> pr = despike_ring(p);
    std::vector<Tri> ptris;
    if (pr.size() == 3) {
      ptris.push_back({pr[0], pr[1], pr[2]});
    } else if (pr.size() == 4) {
      const P3 &a = b.at(pr[0]), &c1 = b.at(pr[1]), &c = b.at(pr[2]), &d = b.at(pr[3]);
      const double q_ac = std::min(min_angle(a, c1, c), min_angle(a, c, d));
      const double q_bd = std::min(min_angle(a, c1, d), min_angle(c1, c, d));
      if (q_ac >= q_bd) {
        ptris.push_back({pr[0], pr[1], pr[2]});
        ptris.push_back({pr[0], pr[2], pr[3]});
      } else {
        ptris.push_back({pr[0], pr[1], pr[3]});
        ptris.push_back({pr[1], pr[2], pr[3]});
      }
    } else if (pr.size() > 4) {
      P3 mean = P3::Zero();
      for (std::int32_t v : pr) mean += b.at(v);
      mean /= static_cast<double>(pr.size());
      std::int32_t centre;
      if (surface_point) {
        const auto [sp, w] = surface_point(mean);
        centre = b.add_point(sp, w);
      } else {
        centre = b.add_point(mean);
      }
      for (std::size_t i = 0; i < pr.size(); ++i) ptris.push_back({centre, pr[i], pr[(i + 1) % pr.size()]});
    }
    const std::size_t n_side = tris.size();
    for (const Tri& q : ptris)
      if (q[0] != q[1] && q[1] != q[2] && q[2] != q[0]) tris.push_back(q);
    // Surface triangles have no lattice node and side triangles do: a fin is two side triangles
    // or two surface ones; only the surviving surface triangles are interface elements.
    std::vector<Tri> surface_tris(tris.begin() + static_cast<std::ptrdiff_t>(n_side), tris.end());
    tris.resize(n_side);
    b.out.n_fins_cancelled += cancel_fins(tris) + cancel_fins(surface_tris);
    for (const Tri& q : surface_tris) {
      tris.push_back(q);
      b.out.mesh.interface.add(ElemType::Tri3, {VertexId{q[0]}, VertexId{q[1]}, VertexId{q[2]}});
    }
    // Centroid of the distinct corner nodes (face corners and their projections).
    std::vector<std::int32_t> corners;
    for (int c = 0; c < 4; ++c) {
      corners.push_back(bo.ring[bo.corner_slot[c]]);
      corners.push_back(p[bo.corner_slot[c]]);
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    P3 centre = P3::Zero();
    for (std::int32_t v : corners) centre += b.at(v);
    centre /= static_cast<double>(corners.size());
    // The centroid need not see every face triangle of a sheared octant: try apexes between the
    // face's centre and the projections' centre and keep the one whose worst cone is best.
    P3 qc = P3::Zero(), pc = P3::Zero();
    for (int c = 0; c < 4; ++c) {
      qc += 0.25 * b.at(bo.ring[bo.corner_slot[c]]);
      pc += 0.25 * b.at(p[bo.corner_slot[c]]);
    }
    const auto worst = [&](const P3& x) {
      double w = std::numeric_limits<double>::infinity();
      for (const Tri& q : tris) {
        if (q[0] == q[1] || q[1] == q[2] || q[2] == q[0]) continue;
        const P3 &a0 = b.at(q[0]), &a1 = b.at(q[1]), &a2 = b.at(q[2]);
        w = std::min(w, (a2 - a0).dot((a1 - a0).cross(x - a0)));
      }
      return w;
    };
    double best = worst(centre);
    if (best <= 0) {
      for (double a : {0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9}) {
        const P3 x = (1 - a) * qc + a * pc;
        const double w = worst(x);
        if (w > best) best = w, centre = x;
      }
    }
    b.cones(tris, centre, bo.cell.level, true, n_interior + static_cast<std::int32_t>(k));
  }
  // The boundary octants' tetrahedra were built first (nodes in the same order: pass 3 adds
  // none); they go after the interior ones, into arrays allocated once at their final size.
  // Appending them to the interior ones instead grew every array by doubling and shrank it
  // again: three fresh copies of each, and their page faults.
  for (std::size_t e = 0; e < m.solid.size(); ++e)
    MESH_ASSERT(m.solid.type[e] == ElemType::Tet4 && m.solid.offset[e] == static_cast<std::int32_t>(4 * e),
                "tetrahedralize: a boundary octant's element is not a tetrahedron");
  const std::size_t n_all_tets = n_int_tets + m.solid.size();
  // v's n_head first values (pass 3 writes them), then what v held: one fresh allocation.
  const auto after_head = [&](auto& v, std::size_t n_head, const auto& fill) {
    const auto tail = std::move(v);
    v = {};
    reserve_huge(v, n_head + tail.size(), n_threads);
    v.assign(n_head, fill);
    v.insert(v.end(), tail.begin(), tail.end());
  };
  after_head(m.solid.type, n_int_tets, ElemType::Tet4);
  after_head(m.solid.node, 4 * n_int_tets, VertexId{});
  after_head(m.level, n_int_tets, std::uint8_t{0});
  after_head(m.from_boundary_cell, n_int_tets, std::uint8_t{0});
  after_head(b.out.cell, n_int_tets, std::int32_t{0});
  m.solid.offset = {};
  reserve_huge(m.solid.offset, n_all_tets + 1, n_threads);
  m.solid.offset.resize(n_all_tets + 1);
  if (reuse) {
    const auto n = static_cast<std::ptrdiff_t>(n_int_tets);
    std::copy(last->mesh.solid.node.begin(), last->mesh.solid.node.begin() + 4 * n, m.solid.node.begin());
    std::copy(last->mesh.level.begin(), last->mesh.level.begin() + n, m.level.begin());
    std::copy(last->cell.begin(), last->cell.begin() + n, b.out.cell.begin());
  } else {
    // The same ranges as pass 1 (for_each_range splits [0, n_int) the same way every time).
    for_each_range(n_int, n_threads, [&](std::size_t begin, std::size_t) {
      const auto it = std::lower_bound(ranges.begin(), ranges.end(), begin, [](const Range& x, std::size_t v) { return x.begin < v; });
      MESH_ASSERT(it != ranges.end() && it->begin == begin, "tetrahedralize: the ranges of pass 1");
      const Range& r = *it;
      std::size_t tri = 0, fan = 0;
      for (std::size_t k = r.begin; k < r.end; ++k) {
        const auto id = [&](std::int32_t v) { return v >= 0 ? v : r.fan_ids[fan + static_cast<std::size_t>(-1 - v)]; };
        std::size_t e = tet_start[k];
        const std::uint8_t level = t.leaf(oc.interior[k]).level;
        for (std::size_t i = 0; i < n_tris[k]; ++i) {
          const Tri& q = r.tris[tri + i];
          if (q[0] == q[1] || q[1] == q[2] || q[2] == q[0]) continue;
          VertexId* v = m.solid.node.data() + 4 * e;
          v[0] = VertexId{id(q[0])}, v[1] = VertexId{id(q[2])}, v[2] = VertexId{id(q[1])}, v[3] = VertexId{centroid[k]};
          m.level[e] = level;
          b.out.cell[e] = static_cast<std::int32_t>(k);
          ++e;
        }
        tri += n_tris[k];
        fan += n_fans[k];
      }
    });
  }
  if (kept && !reuse) {
    kept->n_tets = n_int_tets;
    kept->hash = interior_hash(m, b.out.cell, n_int_tets);
    kept->n_complex_points = oc.points.size();
    kept->n_interior = n_int;
    kept->filled = true;
  }
  for (std::size_t e = 0; e <= n_all_tets; ++e) m.solid.offset[e] = static_cast<std::int32_t>(4 * e);
  ranges.clear();
  ranges.shrink_to_fit();

  // The node arrays grew by doubling (up to twice their size); they are kept through smoothing
  // and edge removal.
  b.out.mesh.points.shrink_to_fit();
  b.out.where.shrink_to_fit();
  return std::move(b.out);
}

}  // namespace febemesh::dim3
