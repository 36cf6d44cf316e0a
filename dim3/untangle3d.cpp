#include "dim3/untangle3d.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <set>
#include <span>

#include "core/cube_faces.hpp"
#include "core/parallel_ranges.hpp"
#include "core/quality.hpp"

namespace febemesh::dim3 {
namespace {

double signed_volume(const P3& a, const P3& b, const P3& c, const P3& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

/// Inverted or flat tets among `elems` when node `v` sits at `x` (the others where they are).
int count_bad(const Mesh<3>& m, const std::vector<std::size_t>& elems, std::int32_t v, const P3& x) {
  int n = 0;
  for (std::size_t e : elems) {
    const VertexId* nodes = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    std::array<P3, 4> p;
    for (int k = 0; k < 4; ++k) p[k] = nodes[k].v == v ? x : m.points[nodes[k].v];
    double len = 0.0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) len = std::max(len, (p[a] - p[b]).norm());
    if (signed_volume(p[0], p[1], p[2], p[3]) <= 1e-12 * len * len * len) ++n;
  }
  return n;
}

/// The size of cell `c` of fe.cell (an interior octant, or a boundary octant's face) and the
/// leaf box of an interior one (empty for a boundary octant).
double cell_size(const Orthtree<3>& t, const OctantComplex& oc, std::int32_t c) {
  const std::size_t n_int = oc.interior.size();
  const Cell<3>& cell = static_cast<std::size_t>(c) < n_int ? t.leaf(oc.interior[c]) : oc.boundary[c - n_int].cell;
  return geometry(t, cell).extent()[0];
}

}  // namespace

std::vector<std::size_t> inverted_elements(const Mesh<3>& m, int n_threads) {
  std::vector<std::uint8_t> flat(m.solid.size(), 0);
  for_each_range(m.solid.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const VertexId* v = m.solid.nodes(id);
      const int n = m.solid.n_nodes_of(id);
      std::array<P3, 8> p;
      for (int k = 0; k < n; ++k) p[static_cast<std::size_t>(k)] = m.points[v[k].v];
      double sq = 0.0;
      for (int a = 0; a < n; ++a)
        for (int b = a + 1; b < n; ++b) sq = std::max(sq, (p[a] - p[b]).squaredNorm());
      const double len = std::sqrt(sq);
      flat[e] = signed_measure<3>(m.solid.type[e], std::span<const P3>(p.data(), static_cast<std::size_t>(n))) <=
                        1e-12 * len * len * len
                    ? 1
                    : 0;
    }
  });
  std::vector<std::size_t> out;
  for (std::size_t e = 0; e < flat.size(); ++e)
    if (flat[e]) out.push_back(e);
  return out;
}

std::size_t untangle(const Orthtree<3>& t, const Flags& in, const SurfaceBoundary& s, double graze, bool graze_region,
                     double graze_length, const std::vector<std::size_t>& bad, OctantComplex& oc, TetMesh& fe,
                     std::vector<UntangleUndo>* undo) {
  const std::int32_t n_lat = oc.n_lattice(), n_pts = static_cast<std::int32_t>(oc.points.size());
  Mesh<3>& m = fe.mesh;
  if (bad.empty()) return 0;
  std::set<std::int32_t> movable;
  for (std::size_t e : bad) {
    const VertexId* nodes = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    for (int k = 0; k < 4; ++k)
      if (nodes[k].v >= n_lat && nodes[k].v < n_pts && !oc.snapped[nodes[k].v]) movable.insert(nodes[k].v);
  }
  // The lists below only for the movable nodes (and the face nodes projecting onto them), in
  // the order a list of every node had them: this ran eight times a repair on one thread, over
  // the whole mesh (elephant L4 CLI, two threads: 26.0 -> 24.9 s).
  std::vector<std::uint8_t> is_movable(static_cast<std::size_t>(n_pts), 0);
  for (const std::int32_t p : movable) is_movable[p] = 1;
  const auto movable_node = [&](std::int32_t v) { return v >= n_lat && v < n_pts && is_movable[v]; };
  std::vector<std::vector<std::size_t>> incident(n_pts);
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* nodes = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    for (int k = 0; k < 4; ++k)
      if (movable_node(nodes[k].v)) incident[nodes[k].v].push_back(e);
  }
  std::vector<std::vector<std::int32_t>> neighbours(n_pts);
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const VertexId* nodes = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b && movable_node(nodes[a].v)) neighbours[nodes[a].v].push_back(nodes[b].v);
  }
  std::vector<std::vector<std::int32_t>> sources(n_pts);
  std::vector<std::uint8_t> is_source(static_cast<std::size_t>(n_lat), 0);
  for (std::int32_t q = 0; q < n_lat; ++q)
    if (oc.projection[q] >= 0 && is_movable[oc.projection[q]]) sources[oc.projection[q]].push_back(q), is_source[q] = 1;
  std::vector<P3> normal(n_lat, P3::Zero());
  for (const BoundaryOctant& b : oc.boundary) {
    if (std::none_of(b.ring.begin(), b.ring.end(), [&](std::int32_t q) { return is_source[q] != 0; })) continue;
    const P3 n = facet_normal<3>(b.face);
    for (std::int32_t q : b.ring)
      if (is_source[q]) normal[q] += n;
  }
  const auto admissible = [&](std::int32_t p, const P3& x) {
    for (std::int32_t q : sources[p]) {
      const P3& from = oc.points[q];
      if (enters_interior(t, in, from, x, graze, graze_region, graze_length)) return false;
      if (s.crosses_before(from, x)) return false;
    }
    return true;
  };
  std::size_t moved = 0;
  for (std::int32_t p : movable) {
    int best = count_bad(m, incident[p], p, m.points[p]);
    if (best == 0) continue;
    std::vector<ClosestPoint<3>> cands;
    if (!neighbours[p].empty()) {
      P3 mean = P3::Zero();
      for (std::int32_t u : neighbours[p]) mean += m.points[u];
      mean /= static_cast<double>(neighbours[p].size());
      cands.push_back(s.closest_point(mean));
      cands.push_back(s.closest_point(0.5 * (mean + m.points[p])));
    }
    for (std::int32_t q : sources[p]) {
      if (normal[q].squaredNorm() == 0) continue;
      const double reach = 4.0 * (m.points[p] - oc.points[q]).norm() + 1e-3 * s.root_box().extent()[0];
      P3 hit;
      if (first_hit(s, oc.points[q], oc.points[q] + reach * normal[q].normalized(), hit))
        cands.push_back(s.closest_point(hit));
    }
    int pick = -1;
    for (int c = 0; c < static_cast<int>(cands.size()); ++c) {
      const int n = count_bad(m, incident[p], p, cands[c].point);
      if (n < best && admissible(p, cands[c].point)) best = n, pick = c;
    }
    if (pick < 0) continue;
    if (undo) undo->push_back({p, m.points[p], oc.points[p], oc.where[p]});
    oc.points[p] = cands[pick].point;
    oc.where[p] = cands[pick].where;
    m.points[p] = cands[pick].point;
    ++moved;
  }
  return moved;
}

namespace {

/// The same bits (a point's three doubles, a location's two parameters; -0.0 is not 0.0 here).
template <typename T> bool same_bits(const T& a, const T& b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }

bool same_location(const BoundaryLocation& a, const BoundaryLocation& b) {
  return a.patch == b.patch && same_bits(a.param, b.param) && a.kind == b.kind && a.feature == b.feature;
}

}  // namespace

bool complex_unchanged(const std::vector<UntangleUndo>& undo, const OctantComplex& oc) {
  return std::all_of(undo.begin(), undo.end(), [&](const UntangleUndo& u) {
    const P3& x = oc.points[static_cast<std::size_t>(u.node)];
    return same_bits(x, u.complex_point) && same_location(oc.where[static_cast<std::size_t>(u.node)], u.complex_where);
  });
}

std::vector<std::size_t> folded_faces(const Mesh<3>& m, const std::vector<BoundaryLocation>& where,
                                      const SurfaceBoundary& s, int n_threads) {
  std::vector<std::uint8_t> folded(m.interface.size(), 0);
  for_each_range(m.interface.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const VertexId* n = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
      const P3 &a = m.points[n[0].v], &b = m.points[n[1].v], &c = m.points[n[2].v];
      P3 ref = P3::Zero();
      for (int k = 0; k < 3; ++k)
        if (where[n[k].v].patch >= 0) ref += s.surface().normal(where[n[k].v].patch);
      folded[f] = surface_alignment(a, b, c, ref) <= 1e-9 ? 1 : 0;
    }
  });
  std::vector<std::size_t> out;
  for (std::size_t f = 0; f < folded.size(); ++f)
    if (folded[f]) out.push_back(f);
  return out;
}

std::vector<std::uint8_t> fixed_nodes(const OctantComplex& oc, const TetMesh& fe, bool features) {
  std::vector<std::uint8_t> fixed(fe.mesh.points.size(), 0);
  for (std::size_t v = 0; v < oc.snapped.size() && v < fixed.size(); ++v)
    fixed[v] = oc.snapped[v] == 2 || (features && oc.snapped[v] == 1) ? 1 : 0;
  return fixed;
}

TetOptimizeStats untangle_pass(TetMesh& fe, const OctantComplex& oc, int sweeps, bool escobar,
                               const SurfaceProjection& project,
                               const std::function<P3(const BoundaryLocation&)>& normal, int n_threads,
                               const std::vector<Box<3>>& bounds) {
  TetOptimizeOptions to;
  to.bounds = bounds;
  to.untangle_only = true;
  to.escobar = escobar;
  to.max_sweeps = sweeps;
  to.fixed = fixed_nodes(oc, fe, false);
  to.project = project;
  to.surface_normal = normal;
  to.n_threads = n_threads;
  return optimize_tets(fe.mesh, fe.where, to);
}

std::string untangle_summary(const std::string& pass, const TetOptimizeStats& ts) {
  return pass + ": inverted tetrahedra " + std::to_string(ts.inverted_before) + " -> " +
         std::to_string(ts.inverted_after) + " (" + std::to_string(ts.sweeps) + " sweeps), folded interface triangles " +
         std::to_string(ts.folded_before) + " -> " + std::to_string(ts.folded_after);
}

std::vector<Box<3>> move_bounds(const Orthtree<3>& t, const OctantComplex& oc, const TetMesh& fe, double reach) {
  const Mesh<3>& m = fe.mesh;
  std::vector<Box<3>> cell_box(oc.interior.size() + oc.boundary.size(), Box<3>::empty());
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = m.solid.nodes(id);
    for (int k = 0; k < m.solid.n_nodes_of(id); ++k) cell_box[fe.cell[e]].expand(m.points[v[k].v]);
  }
  for (std::size_t c = 0; c < cell_box.size(); ++c) {
    if (cell_box[c].lo.x() > cell_box[c].hi.x()) continue;
    const double grow = reach * cell_size(t, oc, static_cast<std::int32_t>(c));
    cell_box[c].lo.array() -= grow;
    cell_box[c].hi.array() += grow;
  }
  std::vector<Box<3>> out(m.points.size(), Box<3>::empty());
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = m.solid.nodes(id);
    for (int k = 0; k < m.solid.n_nodes_of(id); ++k) {
      const std::size_t u = static_cast<std::size_t>(v[k].v);
      if (u < fe.where.size() && fe.where[u].patch >= 0) continue;
      out[u].expand(cell_box[fe.cell[e]].lo);
      out[u].expand(cell_box[fe.cell[e]].hi);
    }
  }
  return out;
}

}  // namespace febemesh::dim3
