// core/mesh.hpp and core/mesh_topology.hpp: element tables, facets, boundary of the solid.

#include <catch2/catch.hpp>

#include "core/mesh.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

namespace {

/// Reference elements of every 3D type in Gmsh's node order, positively oriented.
std::vector<Point<3>> reference(ElemType t) {
  using P = Point<3>;
  switch (t) {
    case ElemType::Tet4: return {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0, 0, 1)};
    case ElemType::Hex8:
      return {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1)};
    case ElemType::Prism6: return {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0, 0, 1), P(1, 0, 1), P(0, 1, 1)};
    case ElemType::Pyramid5: return {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0.5, 0.5, 1)};
    default: return {};
  }
}

}  // namespace

TEST_CASE("element type tables", "[mesh]") {
  CHECK(n_nodes(ElemType::Line2) == 2);
  CHECK(n_nodes(ElemType::Hex8) == 8);
  CHECK(n_nodes(ElemType::Pyramid5) == 5);
  CHECK(dimension(ElemType::Quad4) == 2);
  CHECK(dimension(ElemType::Prism6) == 3);
  const ElemType all[] = {ElemType::Line2, ElemType::Tri3, ElemType::Quad4, ElemType::Tet4,
                          ElemType::Hex8, ElemType::Prism6, ElemType::Pyramid5};
  const int gmsh[] = {1, 2, 3, 4, 5, 6, 7};
  const int vtk[] = {3, 5, 9, 10, 12, 13, 14};
  for (int i = 0; i < 7; ++i) {
    CHECK(gmsh_type(all[i]) == gmsh[i]);
    CHECK(vtk_type(all[i]) == vtk[i]);
  }
  CHECK(std::string(name(ElemType::Tet4)) == "tetrahedron");
}

TEST_CASE("Elements add and clear", "[mesh]") {
  Elements els;
  CHECK(els.empty());
  const ElemId a = els.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{2}});
  const VertexId quad[] = {VertexId{1}, VertexId{3}, VertexId{4}, VertexId{2}};
  const ElemId b = els.add(ElemType::Quad4, quad, 4);
  CHECK(a.v == 0);
  CHECK(b.v == 1);
  CHECK(els.size() == 2);
  CHECK(els.n_nodes_of(b) == 4);
  CHECK(els.nodes(b)[1] == VertexId{3});
  CHECK(els.offset.back() == 7);
  els.clear();
  CHECK(els.empty());
  CHECK(els.offset.size() == 1);
  CHECK(els.node.empty());
}

TEST_CASE("3D facets point outward and close the element", "[mesh]") {
  for (const ElemType t : {ElemType::Tet4, ElemType::Hex8, ElemType::Prism6, ElemType::Pyramid5}) {
    INFO(name(t));
    const auto p = reference(t);
    Point<3> centre = Point<3>::Zero();
    for (const auto& q : p) centre += q / static_cast<double>(p.size());
    Point<3> closure = Point<3>::Zero();
    int facet_nodes = 0;
    for (int f = 0; f < n_facets(t); ++f) {
      const auto local = facet_local_nodes(t, f);
      facet_nodes += static_cast<int>(local.size());
      Point<3> normal = Point<3>::Zero(), fc = Point<3>::Zero();
      for (std::size_t i = 0; i < local.size(); ++i) {
        normal += p[local[i]].cross(p[local[(i + 1) % local.size()]]);
        fc += p[local[i]] / static_cast<double>(local.size());
      }
      CHECK(normal.dot(fc - centre) > 0.0);
      closure += normal;
    }
    CHECK(closure.norm() < 1e-12);  // a closed surface: area vectors sum to zero
    // Every edge is shared by exactly two facets.
    for (int e = 0; e < n_edges(t); ++e) {
      const auto [a, b] = edge_local_nodes(t, e);
      int count = 0;
      for (int f = 0; f < n_facets(t); ++f) {
        const auto local = facet_local_nodes(t, f);
        for (std::size_t i = 0; i < local.size(); ++i)
          count += (local[i] == a && local[(i + 1) % local.size()] == b) || (local[i] == b && local[(i + 1) % local.size()] == a);
      }
      CHECK(count == 2);
    }
    CHECK(facet_nodes == 2 * n_edges(t));  // each edge appears in two facet cycles
    CHECK(signed_measure<3>(t, {p.data(), p.size()}) > 0.0);
    CHECK(min_corner_jacobian<3>(t, {p.data(), p.size()}) > 0.0);
  }
}

TEST_CASE("orientation of a facet flips when reversed", "[mesh]") {
  for (int n : {2, 3, 4}) {
    Facet f;
    f.n = n;
    f.type = n == 2 ? ElemType::Line2 : n == 3 ? ElemType::Tri3 : ElemType::Quad4;
    const int ids[] = {7, 3, 9, 5};
    for (int i = 0; i < n; ++i) f.node[i] = VertexId{ids[i]};
    Facet r = f;
    std::reverse(r.node.begin(), r.node.begin() + n);
    CHECK(key_of(f) == key_of(r));
    CHECK(orientation_of(f) == -orientation_of(r));
    Facet rot = f;  // a cyclic rotation keeps the orientation
    std::rotate(rot.node.begin(), rot.node.begin() + 1, rot.node.begin() + n);
    if (n > 2) CHECK(orientation_of(rot) == orientation_of(f));
  }
}

TEMPLATE_TEST_CASE_SIG("boundary facets of a structured grid", "[mesh]", ((int Dim), Dim), 2, 3) {
  const int n = 3;
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> mesh = test::grid_mesh<Dim>(n, simplices);
    const auto boundary = boundary_facets(mesh.solid);
    const std::size_t per_face = simplices && Dim == 3 ? 2 : 1;  // Kuhn splits each square in two
    CHECK(boundary.size() == per_face * 2 * Dim * (Dim == 2 ? n : n * n));
    // Outward: the facet normal points away from the grid centre.
    const Point<Dim> centre = Point<Dim>::Constant(n / 2.0);
    for (const auto& b : boundary) {
      Point<Dim> fc = Point<Dim>::Zero();
      for (int i = 0; i < b.facet.n; ++i) fc += mesh.points[b.facet.node[i].v] / b.facet.n;
      Point<Dim> normal;
      if constexpr (Dim == 2) {
        const Point<2> t = mesh.points[b.facet.node[1].v] - mesh.points[b.facet.node[0].v];
        normal = Point<2>(t.y(), -t.x());
      } else {
        const auto& p = mesh.points;
        normal = (p[b.facet.node[1].v] - p[b.facet.node[0].v]).cross(p[b.facet.node[2].v] - p[b.facet.node[0].v]);
      }
      CHECK(normal.dot(fc - centre) > 0.0);
    }
    CHECK(euler_characteristic(mesh) == 1);
    CHECK(solid_measure(mesh) == Approx(std::pow(n, Dim)));
  }
}

TEST_CASE("unique edges of two triangles", "[mesh]") {
  Elements els;
  els.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{2}});
  els.add(ElemType::Tri3, {VertexId{2}, VertexId{1}, VertexId{3}});
  const auto edges = unique_edges(els);
  CHECK(edges.size() == 5);
  CHECK(std::is_sorted(edges.begin(), edges.end(), [](const auto& a, const auto& b) {
    return a[0].v != b[0].v ? a[0].v < b[0].v : a[1].v < b[1].v;
  }));
  const auto uses = facet_uses(els);
  CHECK(uses.size() == 6);
  CHECK(boundary_facets(els).size() == 4);
}
