// edge_removal: removing an edge keeps the region filled (inside: the same volume; at a convex
// surface edge: less by the tetrahedron cut off), inverts nothing and raises the worst angle; the
// surface edge of anchor level 5 that held its five tetrahedra under 10 deg is swapped; a
// concave surface edge is swapped (the region grows by the tetrahedron outside it) unless another
// part of the surface reaches into that tetrahedron. Edge
// contraction removes the node of a short edge, inside or on the surface, and leaves a valid
// mesh (the validator: conforming, interface = boundary, no unused node) of the same volume.

#include <catch2/catch.hpp>
#include <rapidcheck.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include "core/incidence_csr.hpp"
#include "core/mesh.hpp"
#include "core/read_msh.hpp"
#include "core/test_mesh_fixtures.hpp"
#include "core/validate.hpp"
#include "dim3/edge_removal.hpp"
#include "dim3/tet_optimize.hpp"
#include "property.hpp"
#include "test_paths.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P3 = Point<3>;

double volume6(const Mesh<3>& m, std::size_t e) {
  const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
  const P3 &a = m.points[v[0].v], &b = m.points[v[1].v], &c = m.points[v[2].v], &d = m.points[v[3].v];
  return (b - a).dot((c - a).cross(d - a));
}
double total_volume6(const Mesh<3>& m) {
  double s = 0.0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) s += volume6(m, e);
  return s;
}
double min_dihedral(const Mesh<3>& m) {
  double lo = 180.0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    lo = std::min(lo, tet_min_dihedral_deg(m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], m.points[v[3].v]));
  }
  return lo;
}
/// Every face of the tetrahedra seen once from each side, or once from one (the hull).
bool faces_match(const Mesh<3>& m) {
  std::map<std::array<std::int32_t, 3>, int> seen;  // sorted face -> +1 / -1 per orientation
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    for (const auto& f : face) {
      std::array<std::int32_t, 3> k = {v[f[0]].v, v[f[1]].v, v[f[2]].v};
      // Orientation sign: the parity of the sort.
      int swaps = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j + 1 < 3 - i; ++j)
          if (k[j] > k[j + 1]) std::swap(k[j], k[j + 1]), ++swaps;
      int& s = seen[k];
      if (s != 0 && (s > 0) == (swaps % 2 == 0)) return false;  // the same side twice
      s += swaps % 2 == 0 ? 1 : -1;
      if (std::abs(s) > 1) return false;
    }
  }
  return true;
}

/// The tetrahedra at nodes 22900, 35632, 35635 and 67692 of anchor level 5 (CLI, before edge
/// removal; regressions/anchor-L5-ridge.msh, renumbered) with their interface triangles: its five
/// tetrahedra under 10 deg sit around the surface edge 35632-35635, from the concave feature
/// line's face z = 0.0217 to its face y = 0.2, whose interface triangles meet at 62 deg. Surface
/// nodes: patch 0 on the face z = 0.0217, 1 on y = 0.2.
Mesh<3> anchor_ridge(std::vector<BoundaryLocation>& where) {
  Mesh<3> m = read_msh<3>(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/anchor-L5-ridge.msh");
  where.assign(m.points.size(), BoundaryLocation{});
  for (const VertexId v : m.interface.node) {
    const P3& x = m.points[v.v];
    where[v.v].patch = std::abs(x[2] - 0.0217069) < 1e-12 ? 0 : std::abs(x[1] - 0.2) < 1e-12 ? 1 : -2;
  }
  return m;
}
P3 anchor_normal(const BoundaryLocation& w) { return w.patch == 0 ? P3(0, 0, 1) : P3(0, 1, 0); }

/// Each tetrahedron its own cell (cell[e] = e), to follow them through removals.
std::vector<std::int32_t> own_cells(const Mesh<3>& m) {
  std::vector<std::int32_t> cell(m.solid.size());
  std::iota(cell.begin(), cell.end(), 0);
  return cell;
}

/// The 3x3x3 Kuhn grid with each inside node moved by up to amount / 2 along each axis (an LCG
/// seeded by `seed`); a case with a tetrahedron that is not positive is discarded (RC_PRE).
Mesh<3> jittered_kuhn_grid(unsigned seed, double amount) {
  Mesh<3> m = test::grid_mesh<3>(3, true);
  std::uint64_t s = seed;
  const auto rnd = [&] {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53) - 0.5;
  };
  for (P3& x : m.points)
    if (x.minCoeff() > 0 && x.maxCoeff() < 3) x += amount * P3(rnd(), rnd(), rnd());
  for (std::size_t e = 0; e < m.solid.size(); ++e) RC_PRE(volume6(m, e) > 0);
  return m;
}

}  // namespace

TEST_CASE("edge removal mends the anchor L5 surface edge that no node move can", "[edge_removal]") {
  std::vector<BoundaryLocation> where;
  Mesh<3> m = anchor_ridge(where);
  for (const BoundaryLocation& w : where) REQUIRE(w.patch >= -1);  // every surface node on a face
  const double before = min_dihedral(m), vol = total_volume6(m);
  const std::size_t n_interface = m.interface.size();
  CHECK(before < 9.5);
  std::vector<std::int32_t> cell = own_cells(m);
  // The optimiser may move the two inside nodes whose tetrahedra are all here (22900, 67692);
  // the surface nodes stay (no projection), and so do the nodes at the cut.
  TetOptimizeOptions to;
  to.target_dihedral_deg = 20.0;
  to.fixed.assign(m.points.size(), 1);
  to.fixed[6] = to.fixed[46] = 0;
  REQUIRE(m.points[6].isApprox(P3(0.1642021294999, 0.19387797815118168, 0.008571711993674942)));
  REQUIRE(m.points[46].isApprox(P3(0.18007276780393308, 0.18633886087132615, 0.013278694732051252)));

  SECTION("node moves alone do not get there") {
    optimize_tets(m, where, to);
    CHECK(min_dihedral(m) < 10.0);
  }
  SECTION("without surface normals surface edges stay") {
    const EdgeRemovalStats st = remove_bad_edges(m, where, &cell, EdgeRemovalOptions{});
    CHECK(st.removed >= 1);
    CHECK(st.surface_swapped == 0);
    CHECK(m.interface.size() == n_interface);
    CHECK(std::abs(total_volume6(m) - vol) <= 1e-12 * vol);
    CHECK(faces_match(m));
  }
  SECTION("with them the surface edge is swapped and no tetrahedron stays under 10 deg") {
    EdgeRemovalOptions eo;
    eo.surface_normal = anchor_normal;
    const EdgeRemovalStats st = remove_bad_edges(m, where, &cell, eo);
    CHECK(st.surface_swapped >= 1);
    CHECK(cell.size() == m.solid.size());
    for (std::size_t e = 0; e < m.solid.size(); ++e) CHECK(volume6(m, e) > 0);
    const double removed = min_dihedral(m);
    optimize_tets(m, where, to);
    const double after = min_dihedral(m);
    INFO("min dihedral " << before << " -> " << removed << " (edges removed: " << st.removed << ") -> " << after
                         << " deg (optimised)");
    CHECK(after >= 10.0);
    CHECK(faces_match(m));
    // A swap cuts the ridge's tetrahedron off: less volume, the same number of interface triangles.
    CHECK(total_volume6(m) < vol);
    CHECK(total_volume6(m) > 0.99 * vol);
    CHECK(m.interface.size() == n_interface);
    for (std::size_t f = 0; f < m.interface.size(); ++f) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(f)});
      P3 ref = P3::Zero();
      for (int k = 0; k < 3; ++k) ref += anchor_normal(where[v[k].v]);
      CHECK(surface_alignment(m.points[v[0].v], m.points[v[1].v], m.points[v[2].v], ref) > 0);
    }
  }
}

// EdgeRemovalOptions::only_at (the hex-dominant mesh's second rounds): only tetrahedra with a
// marked node are tried. On the anchor ridge, no node marked: nothing removed, the mesh as it
// was; the worst tetrahedron's nodes marked: it goes, and the tetrahedra with no marked node
// that no removal touched stay as they were.
TEST_CASE("edge removal with only_at tries the tetrahedra at the marked nodes only", "[edge_removal]") {
  std::vector<BoundaryLocation> where;
  const Mesh<3> start = anchor_ridge(where);
  std::size_t worst = 0;
  double lo = 180.0;
  for (std::size_t e = 0; e < start.solid.size(); ++e) {
    const VertexId* v = start.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const double a = tet_min_dihedral_deg(start.points[v[0].v], start.points[v[1].v], start.points[v[2].v], start.points[v[3].v]);
    if (a < lo) lo = a, worst = e;
  }
  REQUIRE(lo < 10.0);
  EdgeRemovalOptions eo;
  eo.surface_normal = anchor_normal;
  {
    Mesh<3> m = start;
    std::vector<std::int32_t> cell = own_cells(m);
    eo.only_at.assign(m.points.size(), 0);
    const EdgeRemovalStats st = remove_bad_edges(m, where, &cell, eo);
    CHECK(st.removed == 0);
    CHECK(m.solid.node == start.solid.node);
  }
  Mesh<3> m = start;
  std::vector<std::int32_t> cell = own_cells(m);
  eo.only_at.assign(m.points.size(), 0);
  const VertexId* w = start.solid.nodes(ElemId{static_cast<std::int32_t>(worst)});
  for (int k = 0; k < 4; ++k) eo.only_at[static_cast<std::size_t>(w[k].v)] = 1;
  const EdgeRemovalStats st = remove_bad_edges(m, where, &cell, eo);
  CHECK(st.removed >= 1);
  CHECK(std::binary_search(st.cells_changed.begin(), st.cells_changed.end(), static_cast<std::int32_t>(worst)));
  CHECK(faces_match(m));
  for (std::size_t e = 0; e < m.solid.size(); ++e) CHECK(volume6(m, e) > 0);
  // The tetrahedra of unchanged cells are the input's, node for node.
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const std::int32_t c = cell[e];
    if (std::binary_search(st.cells_changed.begin(), st.cells_changed.end(), c)) continue;
    const VertexId* a = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const VertexId* b = start.solid.nodes(ElemId{c});
    for (int k = 0; k < 4; ++k) CHECK(a[k].v == b[k].v);
  }
}

TEST_CASE("edge removal inside a jittered cube keeps the volume and raises the worst angle", "[edge_removal][property]") {
  test::prop("jittered Kuhn cubes", 20, [](unsigned seed) {
    Mesh<3> m = jittered_kuhn_grid(seed, 0.6);
    m.interface.clear();
    m.level.clear();
    m.from_boundary_cell.clear();
    const double vol = total_volume6(m), before = min_dihedral(m);
    const std::size_t n_before = m.solid.size();
    EdgeRemovalOptions eo;
    eo.below_deg = 30.0;
    const EdgeRemovalStats st = remove_bad_edges(m, std::vector<BoundaryLocation>(m.points.size()), nullptr, eo);
    RC_TAG(st.removed > 0 ? "removed" : "none");
    for (std::size_t e = 0; e < m.solid.size(); ++e) RC_ASSERT(volume6(m, e) > 0);
    RC_ASSERT(std::abs(total_volume6(m) - vol) <= 1e-12 * vol);
    RC_ASSERT(min_dihedral(m) >= before - 1e-9);
    RC_ASSERT(faces_match(m));
    RC_ASSERT(st.removed > 0 || m.solid.size() == n_before);
  });
}

namespace {

/// A 4x4x4 Kuhn grid whose node `u` is moved to 1 - t of the way to its neighbour `v` along a
/// grid edge, for the largest t in 0.95, 0.9, ... that keeps every tetrahedron positive: the
/// short edge uv leaves tetrahedra under 10 deg that no edge removal mends.
Mesh<3> pinched_grid(int u, int v, std::vector<BoundaryLocation>& where) {
  Mesh<3> m;
  for (double t = 0.95; t > 0.4; t -= 0.05) {
    m = test::grid_mesh<3>(4, true);
    m.points[u] += t * (m.points[v] - m.points[u]);
    bool positive = true;
    for (std::size_t e = 0; e < m.solid.size(); ++e) positive = positive && volume6(m, e) > 0;
    if (positive) break;
  }
  // Surface nodes: patch = the face (0..5: x = 0, x = 4, y = 0, ...); kind Smooth inside a face,
  // FeatureEdge on the cube's edges, Corner at its corners.
  where.assign(m.points.size(), BoundaryLocation{});
  const Mesh<3> plain = test::grid_mesh<3>(4, true);
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const P3& x = plain.points[i];
    int n_faces = 0;
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side)
        if (x[d] == 4.0 * side) {
          if (n_faces == 0) where[i].patch = 2 * d + side;
          ++n_faces;
        }
    where[i].kind = n_faces <= 1 ? BoundaryLocation::Kind::Smooth
                    : n_faces == 2 ? BoundaryLocation::Kind::FeatureEdge
                                   : BoundaryLocation::Kind::Corner;
  }
  return m;
}
P3 cube_normal(const BoundaryLocation& w) {
  P3 n = P3::Zero();
  n[w.patch / 2] = w.patch % 2 == 0 ? -1.0 : 1.0;
  return n;
}

}  // namespace

namespace {

/// Tetrahedra (positive or not: they are turned) and their boundary faces as interface
/// triangles, outward; every node on surface patch 0 but `inside`.
Mesh<3> tets_with_hull(const std::vector<P3>& points, std::vector<std::array<std::int32_t, 4>> tets, std::int32_t inside,
                       std::vector<BoundaryLocation>& where) {
  Mesh<3> m;
  for (const P3& x : points) m.add_point(x);
  std::map<std::array<std::int32_t, 3>, std::pair<int, std::array<std::int32_t, 3>>> faces;  // sorted -> (uses, outward)
  for (auto& t : tets) {
    if ((points[t[1]] - points[t[0]]).dot((points[t[2]] - points[t[0]]).cross(points[t[3]] - points[t[0]])) < 0) std::swap(t[2], t[3]);
    m.solid.add(ElemType::Tet4, {VertexId{t[0]}, VertexId{t[1]}, VertexId{t[2]}, VertexId{t[3]}});
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    for (const auto& f : face) {
      const std::array<std::int32_t, 3> o = {t[f[0]], t[f[1]], t[f[2]]};
      std::array<std::int32_t, 3> k = o;
      std::sort(k.begin(), k.end());
      auto& e = faces[k];
      ++e.first;
      e.second = o;
    }
  }
  for (const auto& [k, e] : faces)
    if (e.first == 1) m.interface.add(ElemType::Tri3, {VertexId{e.second[0]}, VertexId{e.second[1]}, VertexId{e.second[2]}});
  where.assign(points.size(), BoundaryLocation{});
  for (std::size_t v = 0; v < points.size(); ++v) where[v].patch = static_cast<std::int32_t>(v) == inside ? -1 : 0;
  return m;
}

}  // namespace

TEST_CASE("a concave surface edge is swapped unless the surface reaches into what it adds", "[edge_removal]") {
  // Surface edge ab (x from 0 to 1) between the interface triangles abc (in y = 0) and abf (in
  // z = 0), 270 deg inside, two tetrahedra of 25 deg around it with the inside node i; the
  // surface is the plane y + z = 0 (the interface folds where it has no crease; spool L4's worst
  // two tetrahedra, 14.33 deg, sat around such an edge). The swap ab -> cf adds the tetrahedron
  // a b f c (volume 0.015) and leaves two of 52.4 deg.
  const std::vector<P3> points = {P3(0, 0, 0), P3(1, 0, 0), P3(0.5, 0, 0.3), P3(0.5, 0.3, 0), P3(0.5, -0.2, -0.2),
                                  // A separate tetrahedron with its node 5 inside a b f c.
                                  P3(0.5, 0.05, 0.05), P3(0.5, 0.6, 0.6), P3(0.9, 0.6, 0.6), P3(0.5, 0.9, 0.6)};
  const std::int32_t a = 0, b = 1, c = 2, f = 3, i = 4;
  const auto normal = [](const BoundaryLocation&) { return P3(0, 1, 1).normalized(); };
  std::vector<BoundaryLocation> where;
  EdgeRemovalOptions eo;
  eo.surface_normal = normal;
  eo.concave_below_deg = 30.0;
  SECTION("swapped") {
    Mesh<3> m = tets_with_hull({points.begin(), points.begin() + 5}, {{a, b, c, i}, {a, b, i, f}}, i, where);
    const double before = min_dihedral(m), vol = total_volume6(m);
    const EdgeRemovalStats st = remove_bad_edges(m, where, nullptr, eo);
    INFO("min dihedral " << before << " -> " << min_dihedral(m) << " deg");
    CHECK(st.concave_swapped == 1);
    CHECK(min_dihedral(m) > before + 20.0);
    CHECK(std::abs(total_volume6(m) - vol - 6 * 0.015) < 1e-12);
    CHECK(m.interface.size() == 6);
    CHECK(faces_match(m));
    CHECK(validate(m, ValidateOptions<3>{}).valid);
  }
  SECTION("not with concave_below_deg 0") {
    Mesh<3> m = tets_with_hull({points.begin(), points.begin() + 5}, {{a, b, c, i}, {a, b, i, f}}, i, where);
    eo.concave_below_deg = 0.0;
    CHECK(remove_bad_edges(m, where, nullptr, eo).concave_swapped == 0);
  }
  SECTION("not when another part of the surface reaches into it") {
    Mesh<3> m = tets_with_hull(points, {{a, b, c, i}, {a, b, i, f}, {5, 6, 7, 8}}, i, where);
    const EdgeRemovalStats st = remove_bad_edges(m, where, nullptr, eo);
    CHECK(st.concave_swapped == 0);
    CHECK(faces_match(m));
  }
}

TEST_CASE("edge contraction removes the node of a short edge", "[edge_removal]") {
  // Grid node ids: x + 5 (y + 5 z).
  const auto id = [](int x, int y, int z) { return x + 5 * (y + 5 * z); };
  struct Case {
    const char* name;
    int u, v;
    bool surface;
  };
  for (const Case& c : {Case{"inside", id(2, 2, 2), id(3, 2, 2), false}, Case{"on a face", id(2, 2, 0), id(3, 2, 0), true}}) {
    SECTION(c.name) {
      std::vector<BoundaryLocation> where;
      Mesh<3> m = pinched_grid(c.u, c.v, where);
      const double vol = total_volume6(m), before = min_dihedral(m);
      const std::size_t n_nodes = m.points.size();
      REQUIRE(before < 10.0);
      std::vector<std::int32_t> cell = own_cells(m);
      EdgeRemovalOptions eo;
      eo.below_deg = 30.0;
      eo.surface_normal = cube_normal;
      {
        Mesh<3> removal_only = m;
        std::vector<std::int32_t> cell2 = cell;
        remove_bad_edges(removal_only, where, &cell2, eo);
        CHECK(min_dihedral(removal_only) < 10.0);
      }
      eo.contract_below_deg = 15.0;
      const EdgeRemovalStats st = remove_bad_edges(m, where, &cell, eo);
      remap_nodes(st.node_map, where);
      const double after = min_dihedral(m);
      INFO(c.name << ": min dihedral " << before << " -> " << after << " deg, " << st.contracted << " contracted, "
                  << st.removed << " removed");
      CHECK(st.contracted >= 1);
      CHECK(m.points.size() == n_nodes - st.contracted);
      CHECK(where.size() == m.points.size());
      CHECK(cell.size() == m.solid.size());
      CHECK(after > before + 10.0);
      const ValidationReport v = validate(m, ValidateOptions<3>{});
      INFO(v.summary());
      CHECK(v.valid);
      CHECK(faces_match(m));
      // Every surface node is still on a face of the cube, so the volume is the cube's.
      CHECK(std::abs(total_volume6(m) - vol) <= 1e-12 * vol);
      for (const VertexId n : m.interface.node) CHECK(where[n.v].patch >= 0);
      CHECK(c.surface == (st.contracted > 0 && m.interface.size() < test::grid_mesh<3>(4, true).interface.size()));
    }
  }
  SECTION("never a kept node, a feature-line node or a corner") {
    std::vector<BoundaryLocation> where;
    Mesh<3> m = pinched_grid(id(2, 2, 0), id(3, 2, 0), where);
    EdgeRemovalOptions eo;
    eo.surface_normal = cube_normal;
    eo.contract_below_deg = 30.0;
    eo.keep.assign(m.points.size(), 0);
    eo.keep[id(2, 2, 0)] = eo.keep[id(3, 2, 0)] = 1;
    const std::vector<P3> points = m.points;
    const EdgeRemovalStats st = remove_bad_edges(m, where, nullptr, eo);
    CHECK(m.points.size() == points.size() - st.contracted);
    for (std::size_t v = 0; v < points.size() && !st.node_map.empty(); ++v) {
      const bool must_stay = eo.keep[v] || where[v].kind != BoundaryLocation::Kind::Smooth;
      if (!must_stay) continue;
      CAPTURE(v);
      REQUIRE(st.node_map[v] >= 0);
      CHECK(m.points[static_cast<std::size_t>(st.node_map[v])] == points[v]);
    }
    CHECK(validate(m, ValidateOptions<3>{}).valid);
  }
}

TEST_CASE("edge contraction inside a jittered cube keeps a valid mesh of the same volume", "[edge_removal][property]") {
  test::prop("jittered Kuhn cubes, contractions", 20, [](unsigned seed) {
    Mesh<3> m = jittered_kuhn_grid(seed, 0.8);
    // Hull nodes are surface nodes without a normal: only inside nodes may go.
    std::vector<BoundaryLocation> where(m.points.size());
    for (const VertexId n : m.interface.node) where[n.v].patch = 0;
    const double vol = total_volume6(m), before = min_dihedral(m);
    EdgeRemovalOptions eo;
    eo.below_deg = 30.0;
    eo.contract_below_deg = 30.0;
    const EdgeRemovalStats st = remove_bad_edges(m, where, nullptr, eo);
    RC_TAG(st.contracted > 0 ? "contracted" : "none");
    for (std::size_t e = 0; e < m.solid.size(); ++e) RC_ASSERT(volume6(m, e) > 0);
    RC_ASSERT(std::abs(total_volume6(m) - vol) <= 1e-12 * vol);
    RC_ASSERT(min_dihedral(m) >= before - 1e-9);
    RC_ASSERT(faces_match(m));
    RC_ASSERT(validate(m, ValidateOptions<3>{}).valid);
  });
}

TEST_CASE("the optimiser's node lists handed to edge removal give the mesh it makes alone", "[edge_removal][property]") {
  test::prop("jittered Kuhn cubes, optimised, then edges removed", 20, [](unsigned seed) {
    Mesh<3> m = jittered_kuhn_grid(seed, 0.6);
    std::vector<BoundaryLocation> where(m.points.size());
    for (const VertexId n : m.interface.node) where[n.v].patch = 0;  // (not moved: no projection)
    TetOptimizeOptions to;
    to.max_sweeps = 4;
    to.n_threads = 1 + static_cast<int>(seed % 2);
    NodeTets handed;
    to.incidence = &handed;
    const TetOptimizeStats ts = optimize_tets(m, where, to);
    RC_TAG(ts.moves > 0 ? "moved" : "none");
    // The lists as handed out: those of the mesh's tetrahedra, each node's ascending.
    std::vector<std::int32_t> start, tets;
    incidence_csr(
        m.points.size(), m.solid.size(),
        [&](std::size_t e, auto&& f) {
          for (int k = 0; k < 4; ++k) f(m.solid.nodes(ElemId{static_cast<std::int32_t>(e)})[k].v);
        },
        1, start, tets);
    // (Listed where some tetrahedron was under the target, so that nodes were searched.)
    RC_ASSERT(handed.start.empty() == !(ts.min_dihedral_before_deg < to.target_dihedral_deg));
    if (!handed.start.empty()) {
      RC_ASSERT(handed.start == start);
      RC_ASSERT(handed.tets == tets);
    }
    Mesh<3> alone = m;
    EdgeRemovalOptions eo;
    eo.below_deg = 30.0;
    const EdgeRemovalStats a = remove_bad_edges(alone, where, nullptr, eo);
    eo.incidence = &handed;
    const EdgeRemovalStats b = remove_bad_edges(m, where, nullptr, eo);
    RC_ASSERT(a.removed == b.removed);
    RC_ASSERT(m.solid.node == alone.solid.node);
    RC_ASSERT(m.interface.node == alone.interface.node);
    RC_ASSERT(handed.start.empty() && handed.tets.empty());  // taken
  });
}
