// core/write_vtu.hpp: structure and cell data of the VTU file.

#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>

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

/// The values of the appended DataArray called `name` of a binary VTU (raw, UInt64 sizes),
/// decoded by its declared type, as doubles; and that type.
std::pair<std::vector<double>, std::string> appended_array(const std::string& vtu, const std::string& name) {
  const auto at = vtu.find("Name=\"" + name + "\"");
  REQUIRE(at != std::string::npos);
  const auto tag_start = vtu.rfind('<', at), tag_end = vtu.find("/>", at);
  const std::string tag = vtu.substr(tag_start, tag_end - tag_start);
  const auto attr = [&](const std::string& key) {
    const auto k = tag.find(key + "=\"");
    REQUIRE(k != std::string::npos);
    const auto v = k + key.size() + 2;
    return tag.substr(v, tag.find('"', v) - v);
  };
  CHECK(attr("format") == "appended");
  const std::string type = attr("type");
  const std::size_t block = vtu.find("<AppendedData encoding=\"raw\">");
  REQUIRE(block != std::string::npos);
  const std::size_t first = vtu.find('_', block) + 1 + std::stoull(attr("offset"));
  std::uint64_t n_bytes = 0;
  REQUIRE(first + 8 <= vtu.size());
  std::memcpy(&n_bytes, vtu.data() + first, 8);
  REQUIRE(first + 8 + n_bytes <= vtu.size());
  const char* p = vtu.data() + first + 8;
  std::vector<double> out;
  const auto read = [&]<class T>(T) {
    REQUIRE(n_bytes % sizeof(T) == 0);
    for (std::uint64_t i = 0; i < n_bytes / sizeof(T); ++i) {
      T x;
      std::memcpy(&x, p + i * sizeof(T), sizeof(T));
      out.push_back(static_cast<double>(x));
    }
  };
  if (type == "Float64") read(double{});
  else if (type == "Float32") read(float{});
  else if (type == "Int64") read(std::int64_t{});
  else if (type == "Int32") read(std::int32_t{});
  else if (type == "UInt8") read(std::uint8_t{});
  else FAIL("type " << type);
  return {out, type};
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("binary VTU holds the text VTU's arrays, in raw appended data", "[vtu]", ((int Dim), Dim), 2, 3) {
  // Every array decoded from the appended block equals the text file's (the quality to the
  // text's six decimals); node ids and offsets as Int32, the small cell data as UInt8. A wrong
  // offset, size or type reads other bytes and fails.
  Mesh<Dim> mesh = test::hanging_mesh<Dim>(true);
  mesh.level.assign(mesh.solid.size(), 0);
  mesh.from_boundary_cell.assign(mesh.solid.size(), 0);
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    mesh.level[e] = static_cast<std::uint8_t>(3 + e % 5);
    mesh.from_boundary_cell[e] = e % 2;
  }
  const std::string text = vtu_string(mesh), binary = vtu_string(mesh, VtuEncoding::Binary);
  CHECK(binary == vtu_string(mesh, VtuEncoding::Binary));
  CHECK(binary.find("header_type=\"UInt64\"") != std::string::npos);
  CHECK(binary.find("format=\"ascii\"") == std::string::npos);
  CHECK(binary.substr(binary.size() - 30).find("</AppendedData>\n</VTKFile>\n") != std::string::npos);
  const std::map<std::string, std::string> types = {{"Points", "Float64"}, {"connectivity", "Int32"}, {"offsets", "Int32"},
                                                    {"types", "UInt8"},    {"quality", "Float32"},    {"level", "UInt8"},
                                                    {"from_boundary_cell", "UInt8"}, {"group", "UInt8"}};
  for (const auto& [name, type] : types) {
    CAPTURE(name);
    const auto [values, declared] = appended_array(binary, name);
    CHECK(declared == type);
    const std::vector<double> want = data_array(text, name);
    REQUIRE(values.size() == want.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (name == "quality") CHECK(values[i] == Approx(want[i]).margin(6e-7));  // six decimals, and a float
      else CHECK(values[i] == want[i]);
    }
  }
}

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
