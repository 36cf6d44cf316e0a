// `febemesh compare3d` end to end on sphere966: both tools' keys in comparison.json, TetGen's
// tet count matched within the tolerance (or a warning when it cannot be), the plots, and the
// exit codes for bad input and bad usage.

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "scratch_dir.hpp"

namespace {

int run_status(const std::string& args) {
  const std::string cmd = std::string("'") + FEBEMESH_CLI + "' " + args + " >/dev/null 2>&1";
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string sphere() { return std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off"; }

nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("compare3d on sphere966 matches TetGen's tet count and reports both tools", "[cli][compare]") {
  const febemesh::test::ScratchDir dir("compare3d_cli");
  const auto out = dir.path() / "sphere";
  REQUIRE(run_status("compare3d '" + sphere() + "' -o '" + out.string() + "' --level 4 --quiet") == 0);
  const auto j = read_json(out / "comparison.json");
  for (const char* tool : {"febemesh", "tetgen"}) {
    INFO(tool);
    REQUIRE(j.contains(tool));
    CHECK(j[tool]["ok"] == true);
    for (const char* key : {"elements", "nodes", "wall_seconds", "elements_per_second", "peak_memory_bytes",
                            "min_dihedral_deg", "max_dihedral_deg", "slivers_below_10deg", "volume_rel_error",
                            "hausdorff_rel"})
      CHECK(j[tool].contains(key));
    CHECK(j[tool]["min_dihedral_deg"].get<double>() > 0.0);
    CHECK(j[tool]["max_dihedral_deg"].get<double>() < 180.0);
    CHECK(j[tool]["peak_memory_bytes"].get<double>() > 0.0);
    // Both meshes fill the sphere: volume within 2%, boundary within 2% of the diagonal.
    CHECK(j[tool]["volume_rel_error"].get<double>() < 0.02);
    CHECK(j[tool]["hausdorff_rel"].get<double>() < 0.02);
  }
  const double ours = j["febemesh"]["elements"].get<double>(), theirs = j["tetgen"]["elements"].get<double>();
  CHECK(std::abs(theirs - ours) <= 0.2 * ours);
  CHECK(j["element_count_within_tolerance"] == true);
  CHECK(j["tetgen"]["switches"].get<std::string>().rfind("pq1.414/10a", 0) == 0);
  // Our octree mesh has no slivers here (measured 28.0 deg smallest dihedral at level 4).
  CHECK(j["febemesh"]["min_dihedral_deg"].get<double>() >= 20.0);
  CHECK(j["febemesh"]["slivers_below_10deg"].get<int>() == 0);
  CHECK(j["febemesh"]["target_dihedral_deg"].get<double>() == 30.0);  // mesh3d's default aim
  for (const char* f : {"comparison.md", "min-dihedral.svg", "max-dihedral.svg", "radius-ratio.svg",
                        "scaled-jacobian.svg", "mesh.msh", "tetgen.msh", "tetgen.log"})
    CHECK(std::filesystem::exists(out / f));
  CHECK(read_text(out / "comparison.md").find("Warning") == std::string::npos);
  // Both meshes cut by the same planes, named in comparison.md.
  const std::string md = read_text(out / "comparison.md");
  for (const char* tool : {"febemesh", "tetgen"})
    for (const char* axis : {"x", "y", "z"}) {
      const std::string name = std::string(tool) + "-section-" + axis + ".svg";
      const std::string svg = read_text(out / name);
      CHECK(svg.find("<polygon") != std::string::npos);
      CHECK(svg.find(std::string(tool) == "tetgen" ? "TetGen: solid cut by the plane " + std::string(axis)
                                                   : "febemesh: solid cut by the plane " + std::string(axis)) !=
            std::string::npos);
      CHECK(md.find("[" + name + "](" + name + ")") != std::string::npos);
    }
  // The same plane in both: the titles' "x = ..." agree.
  const auto plane = [&](const std::string& name) {
    const std::string svg = read_text(out / name);
    const auto at = svg.find("cut by the plane ");
    return svg.substr(at, svg.find(':', at) - at);
  };
  CHECK(plane("febemesh-section-z.svg") == plane("tetgen-section-z.svg"));
}

TEST_CASE("compare3d warns when TetGen cannot come down to our tet count", "[cli][compare]") {
  // At level 3 we make ~2,800 tets; TetGen's smallest mesh of the 966 input triangles is ~4x more.
  const febemesh::test::ScratchDir dir("compare3d_cli");
  const auto out = dir.path() / "coarse";
  // (With a lower optimisation aim, passed on to mesh3d: --target-dihedral; and level 3 asked as
  // its octant's size, 21 / 8 in the default root cube: --size, the same mesh as --level 3.)
  REQUIRE(run_status("compare3d '" + sphere() + "' -o '" + out.string() + "' --size 2.625 --target-dihedral 20 --quiet") == 0);
  const auto j = read_json(out / "comparison.json");
  CHECK(j["febemesh"]["target_dihedral_deg"].get<double>() == 20.0);
  CHECK(j["febemesh"]["size"].get<double>() == 2.625);
  CHECK(j["febemesh"]["min_dihedral_deg"].get<double>() >= 15.0);
  CHECK(j["febemesh"]["min_dihedral_deg"].get<double>() < 25.0);  // (30.00 at the default aim)
  CHECK(run_status("compare3d '" + sphere() + "' -o '" + (out / "x").string() + "' --target-dihedral 40 --quiet") == 2);
  CHECK(j["element_count_ratio"].get<double>() > 1.2);
  CHECK(j["element_count_within_tolerance"] == false);
  CHECK(read_text(out / "comparison.md").find("**Warning:** tetgen's element count is") != std::string::npos);
}

TEST_CASE("compare3d refuses bad input and bad usage", "[cli][compare]") {
  const febemesh::test::ScratchDir scratch("compare3d_cli");
  const auto& dir = scratch.path();
  const auto out = dir / "open";
  // Not closed: exit 1 and nothing written.
  CHECK(run_status("compare3d '" + std::string(FEBEMESH_DATA_DIR) + "/3d/open-cylinder.off' -o '" + out.string() +
                   "' --quiet") == 1);
  CHECK(!std::filesystem::exists(out));
  CHECK(run_status("compare3d '" + (dir / "missing.off").string() + "' -o '" + out.string() + "' --quiet") == 1);
  CHECK(!std::filesystem::exists(out));
  // Usage: no output folder, a level out of range, an unknown option.
  CHECK(run_status("compare3d '" + sphere() + "'") == 2);
  CHECK(run_status("compare3d '" + sphere() + "' -o '" + out.string() + "' --level 99") == 2);
  CHECK(run_status("compare3d '" + sphere() + "' -o '" + out.string() + "' --level 3 --size 2") == 2);
  CHECK(run_status("compare3d '" + sphere() + "' -o '" + out.string() + "' --frobnicate") == 2);
  CHECK(!std::filesystem::exists(out));
}
