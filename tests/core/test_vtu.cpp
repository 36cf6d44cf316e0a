// core/write_vtu.hpp: structure and cell data of the VTU file.

#include <catch2/catch.hpp>

#include <sstream>

#include "core/write_vtu.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

namespace {

/// The whitespace-separated values of the DataArray called `name`.
std::vector<double> data_array(const std::string& xml, const std::string& name) {
  const auto at = xml.find("Name=\"" + name + "\"");
  REQUIRE(at != std::string::npos);
  const auto start = xml.find('>', at) + 1;
  const auto end = xml.find("</DataArray>", start);
  std::istringstream in(xml.substr(start, end - start));
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("VTU has points, cells and cell data", "[vtu]", ((int Dim), Dim), 2, 3) {
  Mesh<Dim> mesh = test::grid_mesh<Dim>(2, true);
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    mesh.level[e] = static_cast<std::uint8_t>(e % 5);
    mesh.from_boundary_cell[e] = e % 2;
  }
  const std::string xml = vtu_string(mesh);
  CHECK(xml == vtu_string(mesh));
  const std::size_t ns = mesh.solid.size(), ni = mesh.interface.size();
  CHECK(xml.find("NumberOfPoints=\"" + std::to_string(mesh.points.size()) + "\"") != std::string::npos);
  CHECK(xml.find("NumberOfCells=\"" + std::to_string(ns + ni) + "\"") != std::string::npos);
  CHECK(data_array(xml, "Points").size() == 3 * mesh.points.size());
  CHECK(data_array(xml, "connectivity").size() == mesh.solid.node.size() + mesh.interface.node.size());
  const auto offsets = data_array(xml, "offsets");
  REQUIRE(offsets.size() == ns + ni);
  CHECK(offsets.back() == static_cast<double>(mesh.solid.node.size() + mesh.interface.node.size()));
  const auto types = data_array(xml, "types");
  CHECK(types.front() == (Dim == 2 ? 5 : 10));
  CHECK(types.back() == (Dim == 2 ? 3 : 5));
  const auto quality = data_array(xml, "quality");
  REQUIRE(quality.size() == ns + ni);
  for (double q : quality) CHECK(q > 0.0);
  const auto group = data_array(xml, "group");
  CHECK(group[0] == 1);
  CHECK(group[ns] == 2);
  const auto level = data_array(xml, "level");
  const auto fbc = data_array(xml, "from_boundary_cell");
  REQUIRE(level.size() == ns + ni);
  // An interface cell carries the attributes of the solid element it bounds.
  const auto boundary = boundary_facets(mesh.solid);
  for (std::size_t i = 0; i < ni; ++i) {
    CHECK(level[ns + i] == mesh.level[boundary[i].elem.v]);
    CHECK(fbc[ns + i] == mesh.from_boundary_cell[boundary[i].elem.v]);
  }
  CHECK(xml.rfind("</VTKFile>") != std::string::npos);
}

TEST_CASE("VTU reorders prism nodes for VTK", "[vtu]") {
  Mesh<3> m;
  using P = Point<3>;
  for (const P& p : {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0, 0, 1), P(1, 0, 1), P(0, 1, 1)}) m.add_point(p);
  m.solid.add(ElemType::Prism6, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}, VertexId{4}, VertexId{5}});
  const auto conn = data_array(vtu_string(m), "connectivity");
  CHECK(conn == std::vector<double>{0, 2, 1, 3, 5, 4});
}
