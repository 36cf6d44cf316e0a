// core/validate.hpp: valid meshes pass, every kind of defect is detected and counted exactly.

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <limits>
#include <string>

#include "core/mesh_topology.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

// A mesh without solid elements meshes nothing, and every other check passes on it: no element
// to invert or to leave a facet open, Euler characteristic 0. With an expected 0 (a torus, an
// annulus) it was valid: a 3D run that lost a whole thin torus stood empty (session 43, seed 1159).
TEMPLATE_TEST_CASE_SIG("an empty mesh is not valid", "[validate]", ((int Dim), Dim), 2, 3) {
  Mesh<Dim> empty;
  ValidateOptions<Dim> opt;
  opt.expected_euler = 0;
  opt.boundary_distance = [](const Point<Dim>&) { return 0.0; };
  const ValidationReport r = validate(empty, opt);
  INFO(r.summary());
  CHECK(r.euler == 0);
  CHECK_FALSE(r.conforms());
  CHECK_FALSE(r.valid);
  CHECK(r.n_problems == 1);
  CHECK(r.summary().find("no solid elements") != std::string::npos);
  CHECK_FALSE(is_valid(empty));
  // One element is enough to be a mesh of something.
  const Mesh<Dim> one = test::grid_mesh<Dim>(1, true);
  CHECK(is_valid(one));
}

TEMPLATE_TEST_CASE_SIG("structured grids are valid", "[validate]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> mesh = test::grid_mesh<Dim>(3, simplices);
    ValidateOptions<Dim> opt;
    opt.expected_euler = 1;
    opt.boundary_distance = [](const Point<Dim>& p) {
      double d = std::numeric_limits<double>::infinity();
      for (int k = 0; k < Dim; ++k) d = std::min({d, std::abs(p[k]), std::abs(p[k] - 3.0)});
      return d;
    };
    const ValidationReport r = validate(mesh, opt);
    INFO(r.summary());
    CHECK(r.valid);
    CHECK(r.euler == 1);
    CHECK(r.problems.empty());
    CHECK(r.max_boundary_distance == 0.0);
    CHECK(is_valid(mesh));

    opt.expected_euler = 0;
    CHECK_FALSE(is_valid(mesh, opt));
    CHECK(validate(mesh, opt).conforms());  // the surface's checks alone fail
    opt.expected_euler = 1;
    opt.boundary_tolerance = -1.0;  // every interface node "off the boundary"
    const ValidationReport off = validate(mesh, opt);
    CHECK_FALSE(off.valid);
    CHECK(off.off_boundary_nodes > 0);
    CHECK(off.conforms());
  }
}

TEMPLATE_TEST_CASE_SIG("an inverted element is detected", "[validate]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    Mesh<Dim> mesh = test::grid_mesh<Dim>(3, simplices);
    // Interior node (1,1[,1]) pushed past its neighbours.
    const int id = Dim == 2 ? 1 + 4 : 1 + 4 + 16;
    mesh.points[id] += Point<Dim>::Constant(1.6);
    const ValidationReport r = validate(mesh);
    INFO(r.summary());
    CHECK_FALSE(r.valid);
    CHECK_FALSE(r.conforms());
    CHECK(r.inverted > 0);
    CHECK(r.nonconforming_facets == 0);
    CHECK(r.interface_mismatch == 0);
  }
}

TEMPLATE_TEST_CASE_SIG("a non-convex quad corner counts as inverted", "[validate]", ((int Dim), Dim), 2, 3) {
  // One cube whose corner 0 is pushed inside: positive volume, but a negative corner Jacobian.
  Mesh<Dim> mesh = test::grid_mesh<Dim>(1, false);
  mesh.points[0] = Point<Dim>::Constant(0.8);
  const ValidationReport r = validate(mesh);
  INFO(r.summary());
  CHECK(r.inverted == 1);
}

TEMPLATE_TEST_CASE_SIG("the classic 2:1 hanging node is detected", "[validate]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> mesh = test::hanging_mesh<Dim>(simplices);
    const ValidationReport r = validate(mesh);
    INFO(r.summary());
    CHECK_FALSE(r.valid);
    CHECK(r.hanging_nodes == (Dim == 2 ? 1u : 5u));
    CHECK(r.unused_nodes == 0);
  }
}

TEST_CASE("a node on an inner facet of an overlapping tetrahedron hangs", "[validate]") {
  // Every inner facet of a tetrahedral grid gets a far tetrahedron whose apex sits at the facet's
  // centroid: the apex is on the interior of a facet used twice (not a boundary facet), which
  // only the geometric facet check sees; it is reported as hanging, once, naming a facet.
  const Mesh<3> grid = test::grid_mesh<3>(2, true);
  const std::vector<FacetUse> uses = facet_uses(grid.solid);
  std::size_t n_inner = 0;
  for (std::size_t i = 0; i + 1 < uses.size(); ++i) {
    if (uses[i].key != uses[i + 1].key) continue;
    ++n_inner;
    Mesh<3> mesh = grid;
    const Facet f = facet_of(mesh.solid, uses[i].elem, uses[i].local);
    const Point<3> c = (mesh.points[f.node[0].v] + mesh.points[f.node[1].v] + mesh.points[f.node[2].v]) / 3.0;
    const VertexId apex = mesh.add_point(c), a = mesh.add_point(Point<3>(10, 10, 10)),
                   b = mesh.add_point(Point<3>(11, 10, 10)), d = mesh.add_point(Point<3>(10, 11, 10));
    const VertexId v[4] = {apex, a, b, d};
    mesh.solid.add(ElemType::Tet4, v, 4);
    if (min_corner_jacobian<3>(ElemType::Tet4, element_points<3>(mesh.solid, ElemId{static_cast<std::int32_t>(mesh.solid.size() - 1)}, mesh.points).span()) < 0)
      std::swap(mesh.solid.node[mesh.solid.node.size() - 1], mesh.solid.node[mesh.solid.node.size() - 2]);
    mesh.level.push_back(0);
    mesh.from_boundary_cell.push_back(0);
    ValidateOptions<3> opt;
    opt.check_interface = false;
    const ValidationReport r = validate(mesh, opt);
    INFO(r.summary());
    CHECK(r.inverted == 0);
    CHECK(r.nonconforming_facets == 0);
    CHECK(r.hanging_nodes == 1);
    REQUIRE(r.problems.size() == 1);
    CHECK(r.problems[0].find("hanging node " + std::to_string(apex.v)) != std::string::npos);
    CHECK(r.problems[0].find("on facet") != std::string::npos);
    ++i;
  }
  CHECK(n_inner > 0);
}

TEMPLATE_TEST_CASE_SIG("duplicated element and facets are non-conforming", "[validate]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    Mesh<Dim> mesh = test::grid_mesh<Dim>(2, simplices);
    const ElemId last{static_cast<std::int32_t>(mesh.solid.size() - 1)};
    mesh.solid.add(mesh.solid.type[last.v], mesh.solid.nodes(last), mesh.solid.n_nodes_of(last));
    mesh.level.push_back(1);
    mesh.from_boundary_cell.push_back(0);
    const ValidationReport r = validate(mesh);
    INFO(r.summary());
    CHECK_FALSE(r.valid);
    CHECK(r.nonconforming_facets == static_cast<std::size_t>(n_facets(mesh.solid.type[last.v])));
  }
}

TEMPLATE_TEST_CASE_SIG("a facet used twice in the same orientation is non-conforming", "[validate]", ((int Dim), Dim), 2, 3) {
  // Two unit cubes folded onto the same side of their shared facet: the second is the mirror of
  // the first, its node order renumbered so it is positive. Simplest form: a copy of the element
  // shifted by zero in the same orientation sharing all facets is covered above; here two
  // elements share exactly one facet in the same orientation.
  Mesh<Dim> mesh;
  if constexpr (Dim == 2) {
    for (const auto& p : {Point<2>(0, 0), Point<2>(1, 0), Point<2>(0, 1), Point<2>(0.5, 0.2)}) mesh.add_point(p);
    mesh.solid.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{2}});
    mesh.solid.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{3}});  // overlaps the first
  } else {
    for (const auto& p : {Point<3>(0, 0, 0), Point<3>(1, 0, 0), Point<3>(0, 1, 0), Point<3>(0, 0, 1), Point<3>(0.2, 0.2, 0.5)})
      mesh.add_point(p);
    mesh.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}});
    mesh.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{4}});
  }
  test::set_interface_to_boundary(mesh);
  const ValidationReport r = validate(mesh);
  INFO(r.summary());
  CHECK(r.nonconforming_facets == 1);
  CHECK(r.inverted == 0);
}

TEMPLATE_TEST_CASE_SIG("interface defects: missing, extra, reversed, repeated", "[validate]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> good = test::grid_mesh<Dim>(2, simplices);
    REQUIRE(is_valid(good));
    auto copy_interface = [&](Mesh<Dim>& m, std::size_t skip) {
      m.interface.clear();
      for (std::size_t e = 0; e < good.interface.size(); ++e) {
        if (e == skip) continue;
        const ElemId id{static_cast<std::int32_t>(e)};
        m.interface.add(good.interface.type[e], good.interface.nodes(id), good.interface.n_nodes_of(id));
      }
    };
    {
      Mesh<Dim> m = good;
      copy_interface(m, 3);
      const ValidationReport r = validate(m);
      CHECK(r.interface_missing == 1);
      CHECK(r.interface_extra == 0);
      CHECK(r.interface_reversed == 0);
      CHECK_FALSE(r.valid);
    }
    {
      Mesh<Dim> m = good;
      // An interior facet: facet 0 of an element that is not on the boundary of the grid.
      const auto uses = facet_uses(m.solid);
      std::size_t i = 0;
      while (!(i + 1 < uses.size() && uses[i].key == uses[i + 1].key)) ++i;
      const Facet f = facet_of(m.solid, uses[i].elem, uses[i].local);
      m.interface.add(f.type, f.node.data(), f.n);
      const ValidationReport r = validate(m);
      INFO(r.summary());
      CHECK(r.interface_extra == 1);
      CHECK(r.interface_missing == 0);
      CHECK(r.interface_mismatch == 1);
    }
    {
      Mesh<Dim> m = good;
      const ElemId id{2};
      const int n = m.interface.n_nodes_of(id);
      std::reverse(m.interface.node.begin() + m.interface.offset[2], m.interface.node.begin() + m.interface.offset[2] + n);
      const ValidationReport r = validate(m);
      CHECK(r.interface_reversed == 1);
      CHECK(r.interface_missing == 0);
      CHECK(r.interface_extra == 0);
    }
    {
      Mesh<Dim> m = good;
      const ElemId id{0};
      m.interface.add(m.interface.type[0], m.interface.nodes(id), m.interface.n_nodes_of(id));
      const ValidationReport r = validate(m);
      CHECK(r.interface_extra == 1);
      CHECK(r.interface_missing == 0);
    }
  }
}

TEMPLATE_TEST_CASE_SIG("unused and duplicate nodes", "[validate]", ((int Dim), Dim), 2, 3) {
  Mesh<Dim> mesh = test::grid_mesh<Dim>(2, true);
  {
    Mesh<Dim> m = mesh;
    m.add_point(Point<Dim>::Constant(7.0));
    const ValidationReport r = validate(m);
    CHECK(r.unused_nodes == 1);
    CHECK(r.duplicate_nodes == 0);
    CHECK_FALSE(r.valid);
  }
  {
    // Element 0 uses a copy of its first node: the copy duplicates the original.
    Mesh<Dim> m = mesh;
    const VertexId copy = m.add_point(m.points[m.solid.node[0].v]);
    m.solid.node[0] = copy;
    const ValidationReport r = validate(m);
    INFO(r.summary());
    CHECK(r.duplicate_nodes == 1);
    CHECK_FALSE(r.valid);
  }
}

TEMPLATE_TEST_CASE_SIG("interface nodes off the boundary and bad elements", "[validate]", ((int Dim), Dim), 2, 3) {
  Mesh<Dim> mesh = test::grid_mesh<Dim>(2, false);
  ValidateOptions<Dim> opt;
  opt.boundary_tolerance = 1e-9;
  opt.boundary_distance = [](const Point<Dim>& p) { return std::abs(p.norm() - 1.0); };  // wrong boundary on purpose
  const ValidationReport r = validate(mesh, opt);
  CHECK(r.off_boundary_nodes > 0);
  CHECK(r.max_boundary_distance > 0.5);
  CHECK_FALSE(r.valid);

  Mesh<Dim> bad = mesh;
  bad.interface.add(Dim == 2 ? ElemType::Tri3 : ElemType::Tet4, bad.solid.nodes(ElemId{0}), Dim + 1);
  const ValidationReport rb = validate(bad);
  CHECK(rb.bad_elements == 1);
  CHECK_FALSE(rb.valid);

  Mesh<Dim> attr = mesh;
  attr.level.push_back(3);
  CHECK(validate(attr).attribute_mismatch == 1);
}

TEST_CASE("problems are capped and name elements and coordinates", "[validate]") {
  Mesh<2> mesh = test::grid_mesh<2>(4, true);
  mesh.interface.clear();
  ValidateOptions<2> opt;
  opt.max_problems = 3;
  const ValidationReport r = validate(mesh, opt);
  CHECK(r.interface_missing == 16);
  CHECK(r.problems.size() == 3);
  CHECK(r.n_problems == 16);
  CHECK(r.problems[0].find("boundary facet") != std::string::npos);
  CHECK(r.problems[0].find("(") != std::string::npos);
  CHECK(r.summary().find("13 more") != std::string::npos);
}

TEMPLATE_TEST_CASE_SIG("each kept problem has a site: its kind and a node at it", "[validate]", ((int Dim), Dim), 2, 3) {
  // What a pipeline refines around: a hanging node names itself, an inverted element its first
  // node, the Euler characteristic no node.
  Mesh<Dim> mesh = test::hanging_mesh<Dim>(true);
  std::swap(mesh.solid.node[1], mesh.solid.node[2]);  // the first simplex turned over
  ValidateOptions<Dim> vo;
  vo.expected_euler = 7;
  const ValidationReport r = validate<Dim>(mesh, vo);
  INFO(r.summary());
  REQUIRE(r.sites.size() == r.problems.size());
  std::size_t n_hanging = 0, n_inverted = 0, n_euler = 0;
  for (std::size_t k = 0; k < r.sites.size(); ++k) {
    const auto& site = r.sites[k];
    const std::string kind = site.kind;
    if (kind == "a node hangs on an edge or facet") {
      ++n_hanging;
      // The problem's text names the same node.
      CHECK(r.problems[k].rfind("hanging node " + std::to_string(site.node) + " ", 0) == 0);
    } else if (kind == "an element is inverted") {
      ++n_inverted;
      CHECK(site.node == mesh.solid.node[0].v);
    } else if (kind == "the Euler characteristic differs") {
      ++n_euler;
      CHECK(site.node == -1);
    }
    if (site.node >= 0) CHECK(static_cast<std::size_t>(site.node) < mesh.points.size());
  }
  CHECK(n_hanging == r.hanging_nodes);
  CHECK(n_inverted == r.inverted);
  CHECK(n_euler == 1);
}

TEST_CASE("a part of a mesh validates without the interface check", "[validate]") {
  // Half of a grid's tetrahedra, no interface elements: their cut facets have no interface
  // element, which only the interface check counts.
  const Mesh<3> grid = test::grid_mesh<3>(3, true);
  Mesh<3> part;
  part.points = grid.points;
  for (std::size_t e = 0; e < grid.solid.size() / 2; ++e)
    part.solid.add(ElemType::Tet4, grid.solid.nodes(ElemId{static_cast<std::int32_t>(e)}), 4);
  ValidateOptions<3> vo;
  const ValidationReport whole = validate(part, vo);
  CHECK(whole.interface_missing > 0);
  vo.check_interface = false;
  const ValidationReport r = validate(part, vo);
  INFO(r.summary());
  CHECK(r.interface_mismatch == 0);
  CHECK(r.hanging_nodes == 0);
  CHECK(r.nonconforming_facets == 0);
}

TEST_CASE("a large grid (82,944 tetrahedra) validates", "[validate]") {
  const Mesh<3> mesh = test::grid_mesh<3>(24, true);  // 82944 tets
  const ValidationReport r = validate(mesh);
  CHECK(r.valid);
  CHECK(r.euler == 1);
}

namespace {

/// The Kuhn tetrahedra (six per cell, test::grid_mesh) of an n^3 grid of unit cells, those whose
/// index `keep` accepts; ids of the (n+1)^3 grid nodes, unused ones included.
template <class Keep> Mesh<3> kuhn_cube(int n, Keep&& keep) {
  const Mesh<3> grid = test::grid_mesh<3>(n, true);
  Mesh<3> m;
  m.points = grid.points;
  for (std::size_t e = 0; e < grid.solid.size(); ++e)
    if (keep(e)) m.solid.add(ElemType::Tet4, grid.solid.nodes(ElemId{static_cast<std::int32_t>(e)}), 4);
  return m;
}

}  // namespace

TEST_CASE("euler_characteristic of tetrahedra agrees with its sorting twin", "[validate]") {
  CHECK(euler_characteristic(kuhn_cube(3, [](std::size_t) { return true; })) == 1);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::uint64_t s = seed;
    const double fraction = 0.2 + 0.04 * seed;
    const Mesh<3> m = kuhn_cube(4, [&](std::size_t) {
      s = s * 6364136223846793005ULL + 1442695040888963407ULL;
      return double(s >> 11) / double(1ULL << 53) < fraction;
    });
    CAPTURE(seed);
    CHECK(euler_characteristic(m) == euler_characteristic_ref(m));
    for (const int threads : {2, 3}) CHECK(euler_characteristic(m, threads) == euler_characteristic_ref(m));
    // Nodes counted in runs (one node's uses, a few nodes', a quarter of them).
    for (const std::size_t run : {std::size_t(1), std::size_t(23), m.solid.node.size() / 4 + 1})
      for (const int threads : {1, 2}) CHECK(euler_characteristic(m, threads, run) == euler_characteristic_ref(m));
  }
  // Large enough (about 74,600 of 82,944 tetrahedra kept) that the node lists are built on
  // several threads too.
  std::uint64_t s = 99;
  const Mesh<3> big = kuhn_cube(24, [&](std::size_t) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53) < 0.9;
  });
  const long want = euler_characteristic_ref(big);
  for (const int threads : {1, 2, 3}) CHECK(euler_characteristic(big, threads) == want);
  for (const int threads : {1, 2}) CHECK(euler_characteristic(big, threads, big.solid.node.size() / 5) == want);
  // A tetrahedron with a repeated node: the general count.
  Mesh<3> bad = kuhn_cube(1, [](std::size_t i) { return i == 0; });
  bad.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{1}, VertexId{1}, VertexId{7}});
  CHECK(euler_characteristic(bad) == euler_characteristic_ref(bad));
}

TEMPLATE_TEST_CASE_SIG("the report is the same on 1, 2 and 3 threads", "[validate][threads]", ((int Dim), Dim), 2, 3) {
  // Hanging nodes (the 2:1 mesh), an inverted element, a duplicate node and interface nodes
  // off a made-up boundary: every check that runs on threads finds something.
  Mesh<Dim> mesh = test::hanging_mesh<Dim>(true);
  std::swap(mesh.solid.node[1], mesh.solid.node[2]);  // the first simplex turned over
  const VertexId twin = mesh.add_point(mesh.points[mesh.solid.node[0].v]);
  mesh.solid.node[mesh.solid.offset[3]] = twin;  // a node used by the fourth simplex only, duplicated
  ValidateOptions<Dim> vo;
  vo.expected_euler = 1;
  vo.boundary_distance = [](const Point<Dim>& p) { return p[0] - 1.0; };  // the plane x = 1
  vo.boundary_tolerance = 1e-9;
  vo.max_problems = 1000;
  const ValidationReport one = validate<Dim>(mesh, vo);
  CHECK(one.inverted > 0);
  CHECK(one.hanging_nodes > 0);
  CHECK(one.duplicate_nodes > 0);
  CHECK(one.off_boundary_nodes > 0);
  for (const int threads : {2, 3}) {
    vo.n_threads = threads;
    const ValidationReport r = validate<Dim>(mesh, vo);
    CAPTURE(threads);
    CHECK(r.summary() == one.summary());  // the counts and every problem, in the same order
    CHECK(r.max_boundary_distance == one.max_boundary_distance);
    CHECK(r.euler == one.euler);
  }
}

TEST_CASE("the facet groups of many tetrahedra give the same report on 1, 2 and 3 threads", "[validate][threads]") {
  // 82,944 Kuhn tetrahedra over 15,625 nodes: the facet buckets (one per smallest node) are
  // sorted in several chunks on the threads. Facets used three times (two tetrahedra listed
  // again, one turned over) and the unique edges' runs: the same report and Euler count.
  Mesh<3> m = kuhn_cube(24, [](std::size_t) { return true; });
  const std::size_t n = m.solid.size();
  for (const std::size_t e : {n / 3, 2 * n / 3}) {
    std::array<VertexId, 4> v;
    std::copy_n(m.solid.nodes(ElemId{static_cast<std::int32_t>(e)}), 4, v.begin());
    if (e == n / 3) std::swap(v[1], v[2]);
    m.solid.add(ElemType::Tet4, v.data(), 4);
  }
  ValidateOptions<3> vo;
  vo.max_problems = 1000;
  const ValidationReport one = validate<3>(m, vo);
  CHECK(one.nonconforming_facets > 0);
  CHECK(one.inverted == 1);
  for (const int threads : {2, 3}) {
    vo.n_threads = threads;
    const ValidationReport r = validate<3>(m, vo);
    CAPTURE(threads);
    CHECK(r.summary() == one.summary());
    CHECK(r.euler == one.euler);
  }
}

TEST_CASE("bucketed facet groups give the slow twin's report: triangles and quads, tetrahedra", "[validate]") {
  // (In 3D the twin also queries the nodes near each facet on its own, not a tetrahedron's
  // facets at once; the overlapping-tetrahedron test above has a node on a facet's interior.)
  // Every kind of facet defect, in meshes of triangles, of quads, of both, and of tetrahedra:
  // facets used three times (an element listed again), in the same orientation (an element
  // turned over), a degenerate element (a node twice), interface elements missing, extra and
  // reversed, and hanging nodes (the 2:1 meshes). The bucketed grouping (and in 2D the edges
  // taken from it) against facet_uses and unique_edges: the same report, counts and Euler number.
  const auto check = []<int Dim>(Mesh<Dim> mesh) {
    auto& s = mesh.solid;
    const std::size_t n = s.size();
    const auto copy_of = [&](std::size_t e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      return std::vector<VertexId>(s.nodes(id), s.nodes(id) + s.n_nodes_of(id));
    };
    std::vector<VertexId> again = copy_of(n / 2), over = copy_of(n / 3), flat = copy_of(n - 1);
    std::swap(over[1], over[2]);
    flat[1] = flat[0];
    s.add(s.type[n / 2], again.data(), static_cast<int>(again.size()));
    s.add(s.type[n / 3], over.data(), static_cast<int>(over.size()));
    s.add(s.type[n - 1], flat.data(), static_cast<int>(flat.size()));
    mesh.level.clear();
    mesh.from_boundary_cell.clear();
    auto& in = mesh.interface;
    if (in.size() >= 3) {
      std::vector<VertexId> turned(in.nodes(ElemId{1}), in.nodes(ElemId{1}) + in.n_nodes_of(ElemId{1}));
      std::reverse(turned.begin(), turned.end());
      Elements kept;
      for (std::size_t f = 2; f < in.size(); ++f) kept.add(in.type[f], in.nodes(ElemId{static_cast<std::int32_t>(f)}), in.n_nodes_of(ElemId{static_cast<std::int32_t>(f)}));
      kept.add(in.type[1], turned.data(), static_cast<int>(turned.size()));  // reversed; element 0's facet missing
      kept.add(in.type[2], in.nodes(ElemId{2}), in.n_nodes_of(ElemId{2}));    // listed twice
      in = kept;
    }
    ValidateOptions<Dim> vo;
    vo.expected_euler = 1;
    vo.max_problems = 1000;
    for (const int threads : {1, 2, 3}) {
      vo.n_threads = threads;
      vo.bucketed_facets = false;
      const ValidationReport twin = validate<Dim>(mesh, vo);
      vo.bucketed_facets = true;
      const ValidationReport r = validate<Dim>(mesh, vo);
      CAPTURE(Dim, n, threads);
      CHECK(twin.nonconforming_facets > 0);
      CHECK(twin.interface_missing > 0);
      CHECK(twin.interface_extra > 0);
      CHECK(twin.interface_reversed > 0);
      CHECK(r.summary() == twin.summary());  // the counts and every problem, in the same order
      CHECK(r.euler == twin.euler);
      CHECK(r.n_problems == twin.n_problems);
    }
  };
  check(test::grid_mesh<2>(7, true));
  check(test::grid_mesh<2>(7, false));
  // 80,000 triangles and 67,600 quads: the uses are bucketed by ranges of the elements, one a
  // thread, and the groups reported by chunks of buckets on the threads; a facet's three uses
  // (an element listed again at the end) span the ranges.
  check(test::grid_mesh<2>(200, true));
  check(test::grid_mesh<2>(260, false));
  check(test::hanging_mesh<2>(true));
  check(test::hanging_mesh<2>(false));
  check(test::grid_mesh<3>(4, true));
  check(test::hanging_mesh<3>(true));
  Mesh<3> not_finite = test::grid_mesh<3>(3, true);  // a node's box, and its tetrahedra's, not finite
  not_finite.points[21][1] = std::numeric_limits<double>::quiet_NaN();
  check(not_finite);
  // Triangles and quads in one mesh: the grid's quads, every other one split in two triangles.
  Mesh<2> mixed = test::grid_mesh<2>(6, false);
  Elements both;
  for (std::size_t e = 0; e < mixed.solid.size(); ++e) {
    const VertexId* v = mixed.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    if (e % 2 == 0) {
      both.add(ElemType::Quad4, v, 4);
      continue;
    }
    const std::array<VertexId, 3> a = {v[0], v[1], v[2]}, b = {v[0], v[2], v[3]};
    both.add(ElemType::Tri3, a.data(), 3);
    both.add(ElemType::Tri3, b.data(), 3);
  }
  mixed.solid = both;
  test::set_interface_to_boundary(mixed);
  check(mixed);
}

TEMPLATE_TEST_CASE_SIG("content_hash changes with anything validate reads", "[validate]", ((int Dim), Dim), 2, 3) {
  // A report handed on with a mesh's hash applies only to that mesh: every array validate reads
  // changes the hash when one value in it changes (one ulp of a coordinate, one node id, one
  // attribute, one element more), and a copy hashes the same.
  const Mesh<Dim> mesh = test::grid_mesh<Dim>(3, true);
  REQUIRE(!mesh.interface.empty());
  const std::uint64_t h = content_hash(mesh);
  CHECK(content_hash(Mesh<Dim>(mesh)) == h);
  Mesh<Dim> m = mesh;
  m.points[5][1] = std::nextafter(m.points[5][1], 10.0);
  CHECK(content_hash(m) != h);
  m = mesh;
  std::swap(m.solid.node[0], m.solid.node[1]);
  CHECK(content_hash(m) != h);
  m = mesh;
  std::swap(m.interface.node[0], m.interface.node[1]);
  CHECK(content_hash(m) != h);
  m = mesh;
  m.level.assign(m.solid.size(), 0);
  const std::uint64_t with_levels = content_hash(m);
  CHECK(with_levels != h);
  m.level[m.solid.size() - 1] = 1;
  CHECK(content_hash(m) != with_levels);
  m = mesh;
  m.from_boundary_cell.assign(m.solid.size(), 0);
  const std::uint64_t with_flags = content_hash(m);
  m.from_boundary_cell[0] = 1;
  CHECK(content_hash(m) != with_flags);
  m = mesh;
  m.add_point(Point<Dim>::Zero());
  CHECK(content_hash(m) != h);
}
