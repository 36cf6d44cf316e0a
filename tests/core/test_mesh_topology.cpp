// core/mesh_topology.hpp: the linear-time facet_uses, unique_edges and boundary_facets give the
// same vectors as their comparison-sort twins, on meshes and on arbitrary element soups
// (repeated facets, non-manifold fans, nodes shared by many elements).

#include <catch2/catch.hpp>

#include "core/mesh_topology.hpp"
#include "property.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;
using febemesh::test::grid_mesh;
using febemesh::test::hanging_mesh;

namespace {

bool same_uses(const std::vector<FacetUse>& a, const std::vector<FacetUse>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].key != b[i].key || a[i].elem.v != b[i].elem.v || a[i].local != b[i].local ||
        a[i].orientation != b[i].orientation)
      return false;
  return true;
}

/// The boundary as the plain algorithm finds it: keys used once in the sorted uses, then
/// ordered by (element, local facet).
std::vector<std::pair<int, int>> boundary_ref(const Elements& els) {
  const std::vector<FacetUse> uses = facet_uses_ref(els);
  std::vector<std::pair<int, int>> out;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 1) out.emplace_back(uses[i].elem.v, uses[i].local);
    i = j;
  }
  std::sort(out.begin(), out.end());
  return out;
}

void check_same_as_ref(const Elements& els) {
  CHECK(same_uses(facet_uses(els), facet_uses_ref(els)));
  const std::vector<std::array<VertexId, 2>> edges = unique_edges_ref(els);
  CHECK(unique_edges(els) == edges);
  for (const std::size_t run : {1, 2, 5, 17})  // runs of nodes: several passes, long buckets alone
    CHECK(unique_edges(els, run) == edges);
  for (const int threads : {2, 3, 8})  // element ranges on the threads, in one run or several
    for (const std::size_t run : {0, 1, 5}) {
      CAPTURE(threads, run);
      CHECK(unique_edges(els, run, threads) == edges);
    }
  std::vector<std::pair<int, int>> fast;
  for (const BoundaryFacet& b : boundary_facets(els)) {
    fast.emplace_back(b.elem.v, b.local);
    const Facet f = facet_of(els, b.elem, b.local);
    CHECK(key_of(f) == key_of(b.facet));
  }
  CHECK(fast == boundary_ref(els));
}

/// Random elements of the given types over nodes [0, n_vertices): duplicates and non-manifold
/// configurations included (the functions must not assume a valid mesh).
Elements soup(const std::vector<ElemType>& types, int n_elems, int n_vertices) {
  Elements els;
  for (int e = 0; e < n_elems; ++e) {
    const ElemType t = types[*rc::gen::inRange<std::size_t>(0, types.size())];
    const int n = n_nodes(t);
    const auto nodes = *rc::gen::unique<std::vector<int>>(n, rc::gen::inRange(0, n_vertices));
    std::vector<VertexId> v;
    for (int x : nodes) v.push_back(VertexId{x});
    els.add(t, v.data(), n);
  }
  return els;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("linear topology = comparison-sort twins on meshes", "[mesh]", ((int Dim), Dim), 2, 3) {
  for (bool simplices : {true, false}) {
    check_same_as_ref(grid_mesh<Dim>(4, simplices).solid);
    check_same_as_ref(hanging_mesh<Dim>(simplices).solid);
  }
}

TEST_CASE("linear topology: a node shared by many elements (long bucket)", "[mesh]") {
  Elements els;  // a fan of 100 triangles around node 0, each listed twice
  for (int rep = 0; rep < 2; ++rep)
    for (int k = 1; k <= 100; ++k) els.add(ElemType::Tri3, {VertexId{0}, VertexId{k}, VertexId{k % 100 + 1}});
  check_same_as_ref(els);
  CHECK(boundary_facets(els).empty());  // every facet is used twice

  Elements tets;  // 60 tetrahedra around the axis 0-61, each listed twice: equal keys in a long bucket
  for (int rep = 0; rep < 2; ++rep)
    for (int k = 1; k <= 60; ++k) tets.add(ElemType::Tet4, {VertexId{0}, VertexId{k}, VertexId{k % 60 + 1}, VertexId{61}});
  check_same_as_ref(tets);
}

TEST_CASE("linear topology = comparison-sort twins on element soups", "[mesh][property]") {
  test::prop("2D soups", 200, [] {
    const int n_nodes = *rc::gen::inRange(4, 40);
    check_same_as_ref(soup({ElemType::Tri3, ElemType::Quad4}, *rc::gen::inRange(0, 120), n_nodes));
  });
  test::prop("3D soups", 200, [] {
    const int n_nodes = *rc::gen::inRange(8, 40);
    check_same_as_ref(soup({ElemType::Tet4, ElemType::Hex8, ElemType::Prism6, ElemType::Pyramid5},
                           *rc::gen::inRange(0, 80), n_nodes));
  });
}
