#include "dim3/hex_dominant.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include "core/cube_faces.hpp"
#include "core/error.hpp"
#include "core/quality.hpp"

namespace febemesh::dim3 {
namespace {

using LP = LatticePoint<3>;
using Ring4 = std::array<std::int32_t, 4>;

LP midpoint(const LP& a, const LP& b) { return {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2}; }

Ring4 sorted(Ring4 r) {
  std::sort(r.begin(), r.end());
  return r;
}

bool distinct(const Ring4& r) {
  const Ring4 s = sorted(r);
  return s[0] != s[1] && s[1] != s[2] && s[2] != s[3];
}

/// The square's four node ids when the template face rule keeps it a plain quad (no lattice
/// node at its centre or at an edge midpoint), in the order of `q`.
std::optional<Ring4> plain_square(const LatticeNodes<3>& lattice, const std::array<LP, 4>& q, std::uint32_t len) {
  if (len >= 2) {
    if (lattice.find(midpoint(q[0], q[2])) >= 0) return std::nullopt;
    for (int k = 0; k < 4; ++k)
      if (lattice.find(midpoint(q[k], q[(k + 1) % 4])) >= 0) return std::nullopt;
  }
  Ring4 r;
  for (int k = 0; k < 4; ++k) {
    r[k] = lattice.find(q[k]);
    MESH_ASSERT(r[k] >= 0, "square corner is not a lattice node");
  }
  return r;
}

/// The plain quads of a square face, by the template face rule (triangulate_square): a square
/// with a lattice node at its centre is its four sub-squares, each by the rule; a square with
/// lattice nodes at edge midpoints is fanned (no quad). In the order of `q`.
void plain_squares(const LatticeNodes<3>& lattice, const std::array<LP, 4>& q, std::uint32_t len,
                   std::vector<Ring4>& out) {
  if (len >= 2 && lattice.find(midpoint(q[0], q[2])) >= 0) {
    const LP x = midpoint(q[0], q[2]), m01 = midpoint(q[0], q[1]), m12 = midpoint(q[1], q[2]),
             m23 = midpoint(q[2], q[3]), m30 = midpoint(q[3], q[0]);
    const std::uint32_t h = len / 2;
    plain_squares(lattice, {q[0], m01, x, m30}, h, out);
    plain_squares(lattice, {m01, q[1], m12, x}, h, out);
    plain_squares(lattice, {x, m12, q[2], m23}, h, out);
    plain_squares(lattice, {m30, x, m23, q[3]}, h, out);
    return;
  }
  if (const auto r = plain_square(lattice, q, len)) out.push_back(*r);
}

/// A plain quad face of one cell: outward ring (counter-clockwise seen from outside the cell),
/// the global face it is, and the cell's two cones that cover it.
struct QuadFace {
  Ring4 ring{};
  std::size_t face = 0;
  std::array<std::size_t, 2> cones{};
  bool pyramid_ok = false;
};

struct CellInfo {
  std::vector<std::size_t> cones;  // tets of the cell, ascending
  std::int32_t apex = -1;
  std::vector<QuadFace> quads;
  bool candidate = false;  // all six faces plain quads
  Ring4 lower{}, upper{};  // hex in Gmsh order: lower face, then the nodes above each
  bool is_hex = false;
  /// Its tetrahedra are not the template's cones (TetMesh::cells_changed): it sees no quad, so
  /// the quads it shares with other cells are split, and its tetrahedra stay as they are.
  bool changed = false;
};

struct Faces {
  std::map<Ring4, std::size_t> index;
  std::vector<int> n_cells;
  std::vector<std::uint8_t> split, surface;
  // Smallest dihedral angle of the pyramids on the face (both sides) and of their cones.
  std::vector<double> pyramids_min, cones_min;

  std::size_t get(const Ring4& r) {
    const auto [it, added] = index.emplace(sorted(r), n_cells.size());
    if (added) {
      n_cells.push_back(0);
      split.push_back(0);
      surface.push_back(0);
      pyramids_min.push_back(180.0);
      cones_min.push_back(180.0);
    }
    return it->second;
  }
};

ElemPoints<3> points_of(const std::vector<P3>& pts, std::initializer_list<std::int32_t> ids) {
  ElemPoints<3> out;
  for (std::int32_t v : ids) out.p[out.n++] = pts[v];
  return out;
}

/// Base triangle of a template cone (t0, t2, t1, apex) as a sorted id triple.
std::array<std::int32_t, 3> base_key(const VertexId* n) {
  std::array<std::int32_t, 3> k{n[0].v, n[1].v, n[2].v};
  std::sort(k.begin(), k.end());
  return k;
}

/// Registers the plain quad `ring` of cell `ci` and finds its two cones; a quad the cell's cones
/// do not cover exactly twice is split at once (both sides then keep their triangles).
void add_quad(const Mesh<3>& m, CellInfo& ci, Faces& faces, const Ring4& ring, bool surface) {
  QuadFace q;
  q.ring = ring;
  q.face = faces.get(ring);
  ++faces.n_cells[q.face];
  if (surface) faces.surface[q.face] = 1;
  int n = 0;
  for (std::size_t e : ci.cones) {
    const auto k = base_key(m.solid.nodes(ElemId{static_cast<std::int32_t>(e)}));
    const bool inside = std::all_of(k.begin(), k.end(), [&](std::int32_t v) {
      return std::find(ring.begin(), ring.end(), v) != ring.end();
    });
    if (!inside) continue;
    if (n < 2) q.cones[n] = e;
    ++n;
  }
  if (n != 2) {
    faces.split[q.face] = 1;
    return;
  }
  ci.quads.push_back(q);
}

}  // namespace

HexDominantStats make_hex_dominant(const Orthtree<3>& t, const OctantComplex& oc, TetMesh& fe,
                                   const HexDominantOptions& opt) {
  HexDominantStats st;
  Mesh<3>& m = fe.mesh;
  MESH_ASSERT(fe.cell.size() == m.solid.size(), "cell per element");
  const std::size_t n_interior = oc.interior.size();
  std::vector<CellInfo> cells(n_interior + oc.boundary.size());
  for (const std::int32_t c : fe.cells_changed) cells[c].changed = true;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    MESH_ASSERT(m.solid.type[e] == ElemType::Tet4, "make_hex_dominant takes the template tets");
    CellInfo& ci = cells[fe.cell[e]];
    ci.cones.push_back(e);
    if (ci.changed) continue;
    const std::int32_t apex = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)})[3].v;
    MESH_ASSERT(ci.apex < 0 || ci.apex == apex, "cones of one cell share the centroid");
    ci.apex = apex;
  }

  // The complex's node ids as the mesh numbers them now (contractions remove nodes). A removed
  // node only belongs to changed cells: every tetrahedron at it was replaced.
  const auto node = [&fe](std::int32_t id) {
    if (fe.node_map.empty()) return id;
    MESH_ASSERT(fe.node_map[static_cast<std::size_t>(id)] >= 0, "node " << id << " was contracted away");
    return fe.node_map[static_cast<std::size_t>(id)];
  };
  const auto mapped = [&](Ring4 r) {
    for (std::int32_t& id : r) id = node(id);
    return r;
  };
  Faces faces;
  for (std::size_t k = 0; k < n_interior; ++k) {
    CellInfo& ci = cells[k];
    if (ci.cones.empty() || ci.changed) continue;
    const Cell<3>& c = t.leaf(oc.interior[k]);
    int n_plain = 0;
    std::vector<Ring4> quads;
    for (int f = 0; f < Cube<3>::n_faces; ++f) {
      const auto& fc = FaceCorners<3>::corners[f];
      const std::array<LP, 4> q{corner(c, fc[0]), corner(c, fc[1]), corner(c, fc[2]), corner(c, fc[3])};
      if (plain_square(oc.lattice, q, length(c))) ++n_plain;
      // Sub-squares against finer octants are quads too: pyramids from this cell's centroid.
      quads.clear();
      plain_squares(oc.lattice, q, length(c), quads);
      for (const Ring4& r : quads) add_quad(m, ci, faces, mapped(r), false);
    }
    if (n_plain == Cube<3>::n_faces) {
      // Gmsh order: corners 0 1 3 2 (z low, counter-clockwise seen from above), then above them.
      constexpr std::array<int, 8> gmsh = {0, 1, 3, 2, 4, 5, 7, 6};
      for (int i = 0; i < 4; ++i) {
        ci.lower[i] = node(oc.lattice.find(corner(c, gmsh[i])));
        ci.upper[i] = node(oc.lattice.find(corner(c, gmsh[i + 4])));
      }
      ci.candidate = true;
    }
  }
  for (std::size_t k = 0; k < oc.boundary.size(); ++k) {
    CellInfo& ci = cells[n_interior + k];
    if (ci.cones.empty() || ci.changed) continue;
    const BoundaryOctant& bo = oc.boundary[k];
    const std::size_t n = bo.ring.size();
    std::vector<std::int32_t> ring(n), p(n);
    for (std::size_t i = 0; i < n; ++i) ring[i] = node(bo.ring[i]), p[i] = node(oc.projection[bo.ring[i]]);
    int n_plain = 0;
    const auto& fc = FaceCorners<3>::corners[bo.face];
    const std::array<LP, 4> sq{corner(bo.cell, fc[0]), corner(bo.cell, fc[1]), corner(bo.cell, fc[2]),
                               corner(bo.cell, fc[3])};
    if (plain_square(oc.lattice, sq, length(bo.cell))) ++n_plain;
    std::vector<Ring4> quads;
    plain_squares(oc.lattice, sq, length(bo.cell), quads);
    // Seen from the boundary octant, the interior octant's face turns the other way.
    for (const Ring4& q : quads) add_quad(m, ci, faces, mapped({q[0], q[3], q[2], q[1]}), false);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const Ring4 side{ring[i], ring[j], p[j], p[i]};
      if (!distinct(side)) continue;
      add_quad(m, ci, faces, side, false);
      ++n_plain;
    }
    if (n == 4) {
      const Ring4 top{p[0], p[1], p[2], p[3]};
      if (distinct(top)) {
        add_quad(m, ci, faces, top, true);
        ++n_plain;
      }
    }
    if (n == 4 && n_plain == Cube<3>::n_faces) {
      // The ring turns counter-clockwise seen from the projections: the lower face of the hex.
      for (int i = 0; i < 4; ++i) ci.lower[i] = ring[i], ci.upper[i] = p[i];
      ci.candidate = true;
    }
  }
  // A quad that only one cell sees as a quad, inside the solid, cannot stay one.
  for (std::size_t f = 0; f < faces.n_cells.size(); ++f)
    if (faces.n_cells[f] != 2 && !faces.surface[f]) faces.split[f] = 1;

  const std::vector<P3>& pts = m.points;
  // A merged element's dihedral angles at its quad faces' edges are measured against the quad's
  // mean normal: a warped quad (a boundary octant's side or top) gives angles its two cones do
  // not have. A hex stands only if its smallest dihedral angle reaches min_dihedral_deg or the
  // smallest of its cones'; a quad face between two cells stays one only if its two pyramids
  // do so against the four cones on both sides (the face is split on both sides or neither).
  // So the hex-dominant mesh's smallest angle is not below min(min_dihedral_deg, the tet
  // mesh's). Measured (CLI, level 4, one thread, min dihedral before -> after): spool 9.43 ->
  // 14.88 deg, anchor 8.35 -> 12.89, fandisk 8.66 -> 13.22, rotor 11.02 -> 15.04, for 0.2-0.4%
  // of the hexes (anchor 16681 -> 16649). Judged per hex or pyramid alone, elephant went 2.32 ->
  // 1.77: splitting a face also splits the pyramid beside it, which hid a 1.77 deg cone.
  const bool dihedral_rule = opt.min_dihedral_deg > 0;
  const auto min_dihedral = [](ElemType type, std::span<const P3> ep) { return element_quality<3>(type, ep).min_angle_deg; };
  // Every tetrahedron's smallest angle once: the quads' and the hexes' cones read it.
  std::vector<double> tet_min(m.solid.size());
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    tet_min[e] = min_dihedral(ElemType::Tet4, element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, pts).span());
    st.tets_min_dihedral_deg = std::min(st.tets_min_dihedral_deg, tet_min[e]);
  }
  const auto cones_min_dihedral = [&](const auto& cones) {
    double lo = 180.0;
    for (std::size_t e : cones) lo = std::min(lo, tet_min[e]);
    return lo;
  };
  const auto keeps_dihedral = [&](double merged, double cones) {
    return !dihedral_rule || merged >= std::min(opt.min_dihedral_deg, cones);
  };
  for (CellInfo& ci : cells) {
    for (QuadFace& q : ci.quads) {
      const auto ep = points_of(pts, {q.ring[0], q.ring[3], q.ring[2], q.ring[1], ci.apex});
      // A pyramid worse than both the threshold and the cones it replaces is not worth it.
      double cones_sj = 1.0;
      for (std::size_t e : q.cones) {
        const auto cp = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, pts);
        cones_sj = std::min(cones_sj, scaled_jacobian<3>(ElemType::Tet4, cp.span()));
      }
      const double sj = scaled_jacobian<3>(ElemType::Pyramid5, ep.span());
      q.pyramid_ok = min_corner_jacobian<3>(ElemType::Pyramid5, ep.span()) > 0 && sj > 0 &&
                     sj >= std::min(opt.min_pyramid_scaled_jacobian, cones_sj);
      if (dihedral_rule) {
        faces.pyramids_min[q.face] = std::min(faces.pyramids_min[q.face], min_dihedral(ElemType::Pyramid5, ep.span()));
        faces.cones_min[q.face] = std::min(faces.cones_min[q.face], cones_min_dihedral(q.cones));
      }
    }
    if (!ci.candidate) continue;
    ++st.n_hex_candidates;
    const auto& lo = ci.lower;
    const auto& up = ci.upper;
    const auto ep = points_of(pts, {lo[0], lo[1], lo[2], lo[3], up[0], up[1], up[2], up[3]});
    ci.is_hex = min_corner_jacobian<3>(ElemType::Hex8, ep.span()) > 0 &&
                scaled_jacobian<3>(ElemType::Hex8, ep.span()) >= opt.min_hex_scaled_jacobian &&
                keeps_dihedral(min_dihedral(ElemType::Hex8, ep.span()), cones_min_dihedral(ci.cones));
    if (!ci.is_hex) ++st.n_hex_rejected;
  }
  if (dihedral_rule)
    for (CellInfo& ci : cells)
      for (QuadFace& q : ci.quads)
        if (!keeps_dihedral(faces.pyramids_min[q.face], faces.cones_min[q.face])) q.pyramid_ok = false;

  // Splits only grow and hexes only shrink, so this ends.
  for (bool changed = true; changed;) {
    changed = false;
    for (CellInfo& ci : cells) {
      if (ci.is_hex && std::any_of(ci.quads.begin(), ci.quads.end(), [&](const QuadFace& q) { return faces.split[q.face]; })) {
        ci.is_hex = false;
        ++st.n_hex_demoted;
        changed = true;
      }
      if (ci.is_hex) continue;
      for (const QuadFace& q : ci.quads)
        if (!q.pyramid_ok && !faces.split[q.face]) faces.split[q.face] = 1, changed = true;
    }
  }
  for (std::size_t f = 0; f < faces.split.size(); ++f) st.n_faces_split += faces.split[f];

  // The solid elements, cell by cell in the order of the cones.
  Elements solid;
  std::vector<std::uint8_t> level, from_boundary;
  std::vector<std::int32_t> cell_of;
  std::vector<std::uint8_t> used(pts.size(), 0);
  const auto emit = [&](ElemType type, std::initializer_list<std::int32_t> ids, std::size_t like, std::int32_t cell) {
    std::array<VertexId, 8> v;
    int n = 0;
    for (std::int32_t id : ids) v[n++] = VertexId{id}, used[id] = 1;
    solid.add(type, v.data(), n);
    level.push_back(m.level.empty() ? 0 : m.level[like]);
    from_boundary.push_back(m.from_boundary_cell.empty() ? 0 : m.from_boundary_cell[like]);
    cell_of.push_back(cell);
    const auto ep = element_points<3>(solid, ElemId{static_cast<std::int32_t>(solid.size() - 1)}, pts);
    const double vol = signed_measure<3>(type, ep.span());
    st.total_volume += vol;
    if (type == ElemType::Hex8) st.hex_volume += vol;
  };
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const CellInfo& ci = cells[k];
    if (ci.cones.empty()) continue;
    const std::int32_t cell = static_cast<std::int32_t>(k);
    const std::size_t like = ci.cones.front();
    if (ci.is_hex) {
      const auto& lo = ci.lower;
      const auto& up = ci.upper;
      emit(ElemType::Hex8, {lo[0], lo[1], lo[2], lo[3], up[0], up[1], up[2], up[3]}, like, cell);
      ++st.n_hex;
      continue;
    }
    std::vector<std::size_t> merged;
    for (const QuadFace& q : ci.quads) {
      if (faces.split[q.face]) continue;
      // The apex sees the outward ring turning clockwise: reversed, it is the pyramid's base.
      emit(ElemType::Pyramid5, {q.ring[0], q.ring[3], q.ring[2], q.ring[1], ci.apex}, like, cell);
      ++st.n_pyramid;
      merged.insert(merged.end(), q.cones.begin(), q.cones.end());
    }
    for (std::size_t e : ci.cones) {
      if (std::find(merged.begin(), merged.end(), e) != merged.end()) continue;
      const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
      emit(ElemType::Tet4, {v[0].v, v[1].v, v[2].v, v[3].v}, e, cell);
      ++st.n_tet;
    }
  }

  // The BE mesh: a kept surface quad replaces its two triangles, where the first one was.
  std::map<std::array<std::int32_t, 3>, std::size_t> tri_to_quad;  // -> index in `quads`
  std::vector<Ring4> quads;
  for (const CellInfo& ci : cells)
    for (const QuadFace& q : ci.quads) {
      if (!faces.surface[q.face] || faces.split[q.face]) continue;
      for (std::size_t e : q.cones) tri_to_quad[base_key(m.solid.nodes(ElemId{static_cast<std::int32_t>(e)}))] = quads.size();
      quads.push_back(q.ring);
    }
  Elements interface;
  std::vector<std::uint8_t> quad_done(quads.size(), 0);
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
    MESH_ASSERT(m.interface.type[f] == ElemType::Tri3, "template interface triangles");
    std::array<std::int32_t, 3> key{v[0].v, v[1].v, v[2].v};
    std::sort(key.begin(), key.end());
    const auto it = tri_to_quad.find(key);
    if (it == tri_to_quad.end()) {
      interface.add(ElemType::Tri3, {v[0], v[1], v[2]});
      ++st.n_interface_triangles;
    } else if (!quad_done[it->second]) {
      quad_done[it->second] = 1;
      const Ring4& r = quads[it->second];
      interface.add(ElemType::Quad4, {VertexId{r[0]}, VertexId{r[1]}, VertexId{r[2]}, VertexId{r[3]}});
      ++st.n_interface_quads;
    }
    for (int i = 0; i < 3; ++i) used[v[i].v] = 1;
  }

  // Drop the nodes nothing uses any more (the centroids of hexes), keeping the others' order.
  std::vector<std::int32_t> renumber(pts.size(), -1);
  std::vector<P3> points;
  std::vector<BoundaryLocation> where;
  for (std::size_t v = 0; v < pts.size(); ++v) {
    if (!used[v]) continue;
    renumber[v] = static_cast<std::int32_t>(points.size());
    points.push_back(pts[v]);
    where.push_back(v < fe.where.size() ? fe.where[v] : BoundaryLocation{});
  }
  for (VertexId& v : solid.node) v.v = renumber[v.v];
  for (VertexId& v : interface.node) v.v = renumber[v.v];
  m.points = std::move(points);
  m.solid = std::move(solid);
  m.interface = std::move(interface);
  m.level = std::move(level);
  m.from_boundary_cell = std::move(from_boundary);
  fe.where = std::move(where);
  fe.cell = std::move(cell_of);
  return st;
}

}  // namespace febemesh::dim3
