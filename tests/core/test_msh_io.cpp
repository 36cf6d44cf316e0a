// core/write_msh.hpp and core/read_msh.hpp: round trips, golden bytes, Gmsh reads our files.

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/read_msh.hpp"
#include "core/validate.hpp"
#include "core/write_msh.hpp"
#include "scratch_dir.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;
namespace fs = std::filesystem;

namespace {

template <int Dim> void check_same(const Mesh<Dim>& a, const Mesh<Dim>& b) {
  REQUIRE(a.points.size() == b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) REQUIRE(a.points[i] == b.points[i]);  // bit for bit
  for (const auto member : {&Mesh<Dim>::solid, &Mesh<Dim>::interface}) {
    const Elements& x = a.*member;
    const Elements& y = b.*member;
    REQUIRE(x.type == y.type);
    REQUIRE(x.offset == y.offset);
    REQUIRE(x.node == y.node);
  }
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A tiny 2D mesh: the unit square as two triangles, irrational coordinates on one node.
Mesh<2> two_triangles() {
  Mesh<2> m;
  m.add_point(Point<2>(0, 0));
  m.add_point(Point<2>(1, 0));
  m.add_point(Point<2>(1, 1));
  m.add_point(Point<2>(0.1, 2.0 / 3.0));
  m.solid.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{2}});
  m.solid.add(ElemType::Tri3, {VertexId{0}, VertexId{2}, VertexId{3}});
  test::set_interface_to_boundary(m);
  return m;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("MSH round trip preserves the mesh", "[msh]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    Mesh<Dim> mesh = test::grid_mesh<Dim>(3, simplices, 0.1);
    for (std::size_t i = 0; i < mesh.points.size(); ++i)  // non-trivial doubles
      mesh.points[i] += Point<Dim>::Constant(1e-3 * std::sin(static_cast<double>(i)));
    const std::string text = msh_string(mesh);
    CHECK(text == msh_string(mesh));  // deterministic
    const Mesh<Dim> back = parse_msh<Dim>(text);
    check_same(mesh, back);
    CHECK(msh_string(back) == text);
  }
}

TEST_CASE("MSH round trip of mixed element types", "[msh]") {
  Mesh<3> m;
  using P = Point<3>;
  for (const P& p : {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0.5, 0.5, 1), P(0.5, 0.5, -1), P(1.5, 0.5, 0.5)})
    m.add_point(p);
  // Two pyramids on one square (a square against two triangles does not conform) and a tet on
  // a triangle of the upper one.
  m.solid.add(ElemType::Pyramid5, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}, VertexId{4}});
  m.solid.add(ElemType::Pyramid5, {VertexId{0}, VertexId{3}, VertexId{2}, VertexId{1}, VertexId{5}});
  m.solid.add(ElemType::Tet4, {VertexId{1}, VertexId{2}, VertexId{4}, VertexId{6}});
  test::set_interface_to_boundary(m);
  REQUIRE(is_valid(m));
  const Mesh<3> back = parse_msh<3>(msh_string(m));
  check_same(m, back);
}

TEST_CASE("MSH golden file of a tiny 2D mesh", "[msh]") {
  const fs::path golden = fs::path(FEBEMESH_SOURCE_DIR) / "tests/core/golden/two_triangles.msh";
  const std::string text = msh_string(two_triangles());
  if (std::getenv("FEBEMESH_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(golden, std::ios::binary) << text;
  }
  REQUIRE(fs::exists(golden));
  CHECK(text == slurp(golden));
  check_same(two_triangles(), read_msh<2>(golden));
}

TEMPLATE_TEST_CASE_SIG("write_msh writes the same bytes as msh_string", "[msh]", ((int Dim), Dim), 2, 3) {
  const Mesh<Dim> mesh = test::grid_mesh<Dim>(4, true);
  const test::ScratchDir dir("msh_test");
  const fs::path file = dir.path() / ("grid" + std::to_string(Dim) + ".msh");
  write_msh(mesh, file);
  CHECK(slurp(file) == msh_string(mesh));
  check_same(mesh, read_msh<Dim>(file));
  CHECK_THROWS_AS(write_msh(mesh, fs::path("/nonexistent-dir/x.msh")), InputError);
}

TEST_CASE("write_msh on several threads writes the bytes of one", "[msh]") {
  // Triangles and quads interleaved (each type's block is cut by element index), on more than
  // a few blocks of 16384 lines, with coordinates that are not on a lattice.
  Mesh<2> mesh;
  const int n = 210;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.add_point(Point<2>(i + 0.25 * std::sin(i * 7.0 + j), j + 0.25 * std::cos(j * 3.0 + i)));
  const auto id = [&](int i, int j) { return VertexId{j * (n + 1) + i}; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const VertexId a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 3 == 0) {
        mesh.solid.add(ElemType::Tri3, {a, b, c});
        mesh.solid.add(ElemType::Tri3, {a, c, d});
      } else {
        mesh.solid.add(ElemType::Quad4, {a, b, c, d});
      }
    }
  test::set_interface_to_boundary(mesh);
  REQUIRE(mesh.solid.size() > 3 * 16384);
  const std::string one = msh_string(mesh);
  const test::ScratchDir dir("msh_test");
  const fs::path file = dir.path() / "threads.msh";
  for (const int threads : {1, 2, 3, 8}) {
    write_msh(mesh, file, MshEncoding::Ascii, threads);
    CHECK(slurp(file) == one);
  }
  check_same(mesh, read_msh<2>(file));
  // A failing write stops every thread and throws (no hang, no crash).
  if (fs::exists("/dev/full")) CHECK_THROWS_AS(write_msh(mesh, fs::path("/dev/full"), MshEncoding::Ascii, 2), InputError);
}

TEST_CASE("MSH reader reports malformed input with the line", "[msh]") {
  const std::string good = msh_string(two_triangles());
  CHECK_THROWS_AS(parse_msh<2>("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"), InputError);
  CHECK_THROWS_AS(parse_msh<2>("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n"), InputError);
  CHECK_THROWS_AS(parse_msh<2>(""), InputError);
  CHECK_THROWS_AS(parse_msh<2>(good.substr(0, good.size() / 2)), InputError);
  CHECK_THROWS_AS(parse_msh<3>(good), InputError);  // "solid" has dimension 2
  std::string bad = good;
  bad.replace(bad.find("\n1 1 2 3\n"), 9, "\n1 1 2 99\n");  // unknown node tag in element 1
  try {
    parse_msh<2>(bad, "bad.msh");
    FAIL("no exception");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("bad.msh") != std::string::npos);
    CHECK(std::string(e.what()).find("99") != std::string::npos);
  }
  std::string word = good;
  word.replace(word.find("\n1 1 2 3\n"), 9, "\n1 1 2 x\n");
  try {
    parse_msh<2>(word, "w.msh");
    FAIL("no exception");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("w.msh:") != std::string::npos);
  }
}

TEST_CASE("MSH reader splits a file without physical names by dimension", "[msh]") {
  std::string text = msh_string(two_triangles());
  const auto a = text.find("$PhysicalNames"), b = text.find("$EndPhysicalNames\n");
  text.erase(a, b + std::string("$EndPhysicalNames\n").size() - a);
  check_same(two_triangles(), parse_msh<2>(text));
}

TEMPLATE_TEST_CASE_SIG("gmsh reads our MSH file and writes back the same mesh", "[msh][gmsh]", ((int Dim), Dim), 2, 3) {
  if (!fs::exists("/usr/bin/gmsh")) {
    WARN("gmsh is not installed: skipping");
    return;
  }
  const Mesh<Dim> mesh = test::grid_mesh<Dim>(2, true, 0.5);
  const test::ScratchDir scratch("msh_test");
  const fs::path& dir = scratch.path();
  const fs::path in = dir / ("in" + std::to_string(Dim) + ".msh"), out = dir / ("out" + std::to_string(Dim) + ".msh");
  const fs::path log = dir / "gmsh.log";
  write_msh(mesh, in);
  const std::string cmd = "/usr/bin/gmsh " + in.string() + " -save -format msh41 -o " + out.string() + " > " + log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  INFO(slurp(log));
  REQUIRE(rc == 0);
  CHECK(slurp(log).find("Error") == std::string::npos);
  const Mesh<Dim> back = read_msh<Dim>(out);  // Gmsh's own MSH 4.1 output
  CHECK(back.points.size() == mesh.points.size());
  CHECK(back.solid.size() == mesh.solid.size());
  CHECK(back.interface.size() == mesh.interface.size());
  CHECK(is_valid(back));
}

TEST_CASE("MSH writer throughput", "[msh][benchmark]") {
  const Mesh<3> mesh = test::grid_mesh<3>(30, true, 0.0123);  // 162000 tets
  const auto t0 = std::chrono::steady_clock::now();
  const std::string text = msh_string(mesh);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double mb_per_s = static_cast<double>(text.size()) / 1e6 / s;
  WARN("msh_string: " << text.size() / 1e6 << " MB in " << s << " s = " << mb_per_s << " MB/s");
  CHECK(text.size() > 1000000);
}

TEMPLATE_TEST_CASE_SIG("binary MSH round trip preserves the mesh", "[msh]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    Mesh<Dim> mesh = test::grid_mesh<Dim>(3, simplices, 0.1);
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
      mesh.points[i] += Point<Dim>::Constant(1e-3 * std::sin(static_cast<double>(i)));
    const std::string bin = msh_string(mesh, MshEncoding::Binary);
    CHECK(bin.rfind("$MeshFormat\n4.1 1 8\n", 0) == 0);
    const Mesh<Dim> back = parse_msh<Dim>(bin);
    check_same(mesh, back);
    CHECK(msh_string(back, MshEncoding::Binary) == bin);
    CHECK(msh_string(back) == msh_string(mesh));  // the ASCII text of the same mesh
  }
}

TEST_CASE("binary MSH of mixed element types and the writer's file", "[msh]") {
  Mesh<3> m;
  using P = Point<3>;
  for (const P& p : {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0.5, 0.5, 1), P(0.5, 0.5, -1)}) m.add_point(p);
  m.solid.add(ElemType::Pyramid5, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}, VertexId{4}});
  m.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{2}, VertexId{1}, VertexId{5}});
  m.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{3}, VertexId{2}, VertexId{5}});
  test::set_interface_to_boundary(m);
  const test::ScratchDir dir("msh_test");
  const fs::path file = dir.path() / "mixed-binary.msh";
  write_msh(m, file, MshEncoding::Binary);
  CHECK(slurp(file) == msh_string(m, MshEncoding::Binary));
  check_same(m, read_msh<3>(file));
}

TEST_CASE("binary MSH reader rejects truncated data with a message", "[msh]") {
  const std::string bin = msh_string(two_triangles(), MshEncoding::Binary);
  const std::size_t nodes = bin.find("$Nodes\n");
  REQUIRE(nodes != std::string::npos);
  for (const std::size_t cut : {nodes + 10, nodes + 40, bin.find("$Elements\n") + 30}) {
    CHECK_THROWS_AS(parse_msh<2>(std::string_view(bin).substr(0, cut)), InputError);
  }
  std::string swapped = bin;
  const std::size_t one = swapped.find("4.1 1 8\n") + 8;
  swapped[one] = 0, swapped[one + 3] = 1;  // the byte-order mark of the other endianness
  CHECK_THROWS_AS(parse_msh<2>(swapped), InputError);
}

TEMPLATE_TEST_CASE_SIG("gmsh reads our binary MSH file and writes binary we read back", "[msh][gmsh]", ((int Dim), Dim), 2, 3) {
  if (!fs::exists("/usr/bin/gmsh")) {
    WARN("gmsh is not installed: skipping");
    return;
  }
  const Mesh<Dim> mesh = test::grid_mesh<Dim>(2, true, 0.5);
  const test::ScratchDir scratch("msh_test");
  const fs::path& dir = scratch.path();
  const fs::path in = dir / ("bin-in" + std::to_string(Dim) + ".msh"), out = dir / ("bin-out" + std::to_string(Dim) + ".msh");
  const fs::path log = dir / "gmsh-bin.log";
  write_msh(mesh, in, MshEncoding::Binary);
  const std::string cmd = "/usr/bin/gmsh " + in.string() + " -save -bin -format msh41 -o " + out.string() + " > " +
                          log.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  INFO(slurp(log));
  REQUIRE(rc == 0);
  CHECK(slurp(log).find("Error") == std::string::npos);
  CHECK(slurp(out).rfind("$MeshFormat\n4.1 1 8\n", 0) == 0);  // Gmsh wrote binary
  const Mesh<Dim> back = read_msh<Dim>(out);
  CHECK(back.points.size() == mesh.points.size());
  CHECK(back.solid.size() == mesh.solid.size());
  CHECK(back.interface.size() == mesh.interface.size());
  CHECK(is_valid(back));
}
