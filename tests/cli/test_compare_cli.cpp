// `febemesh compare2d` end to end on the bundled flange at a low level: the JSON holds both
// tools' keys, Gmsh's element count is matched within the tolerance, exit codes are right.

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
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

bool have_gmsh() { return std::system("gmsh --version >/dev/null 2>&1") == 0; }

}  // namespace

TEST_CASE("compare2d on the flange matches Gmsh's element count and reports both tools", "[cli][compare]") {
  if (!have_gmsh()) {
    WARN("gmsh is not installed: compare2d test skipped");
    return;
  }
  const febemesh::test::ScratchDir dir("compare_cli");
  const auto out = dir.path() / "flange";
  const int status =
      run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR + "/examples/flange.json' -o '" + out.string() +
                 "' --level 4 --quiet");
  REQUIRE(status == 0);
  std::ifstream in(out / "comparison.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* tool : {"febemesh", "gmsh"}) {
    INFO(tool);
    REQUIRE(j.contains(tool));
    CHECK(j[tool]["ok"] == true);
    for (const char* key : {"elements", "wall_seconds", "elements_per_second", "min_angle_deg", "max_angle_deg",
                            "area_rel_error", "hausdorff_rel"})
      CHECK(j[tool].contains(key));
    CHECK(j[tool]["min_angle_deg"].get<double>() > 0.0);
    CHECK(j[tool]["max_angle_deg"].get<double>() < 180.0);
    // Both meshes are close to the exact curves.
    CHECK(j[tool]["area_rel_error"].get<double>() < 0.02);
    CHECK(j[tool]["hausdorff_rel"].get<double>() < 0.02);
  }
  const double ours = j["febemesh"]["elements"].get<double>(), gmsh = j["gmsh"]["elements"].get<double>();
  CHECK(std::abs(gmsh - ours) <= 0.2 * ours);
  for (const char* f : {"comparison.md", "min-angle.svg", "scaled-jacobian.svg", "mesh.msh", "gmsh.msh", "gmsh.geo"})
    CHECK(std::filesystem::exists(out / f));
  // The .geo carries the exact pieces, not a polyline.
  std::ifstream geo(out / "gmsh.geo");
  std::stringstream ss;
  ss << geo.rdbuf();
  CHECK(ss.str().find("Bezier(") != std::string::npos);
  // Both meshes drawn, every element counted once in the legend's bins, named in comparison.md.
  std::ifstream md_in(out / "comparison.md");
  std::stringstream md;
  md << md_in.rdbuf();
  for (const char* tool : {"febemesh", "gmsh"}) {
    INFO(tool);
    const std::string name = std::string(tool) + "-mesh.svg";
    std::ifstream svg_in(out / name);
    std::stringstream svg;
    svg << svg_in.rdbuf();
    const std::string text = svg.str();
    CHECK(text.find("<polygon") != std::string::npos);
    std::size_t counted = 0, bins = 0;
    for (std::size_t at = text.find(" deg: "); at != std::string::npos; at = text.find(" deg: ", at + 1), ++bins)
      counted += std::stoul(text.substr(at + 6));
    CHECK(bins == 5);
    CHECK(counted == j[tool]["elements"].get<std::size_t>());
    CHECK(md.str().find("[" + name + "](" + name + ")") != std::string::npos);
  }
}

TEST_CASE("compare2d reports a failing Gmsh and exits with status 1", "[cli][compare]") {
  const febemesh::test::ScratchDir dir("compare_cli");
  const auto out = dir.path() / "nogmsh";
  const int status = run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR + "/examples/flange.json' -o '" +
                                out.string() + "' --level 3 --quiet --gmsh /nonexistent/gmsh");
  CHECK(status == 1);
  std::ifstream in(out / "comparison.json");
  REQUIRE(in);
  const auto j = nlohmann::json::parse(in);
  CHECK(j["febemesh"]["ok"] == true);
  CHECK(j["gmsh"]["ok"] == false);
  CHECK(j["gmsh"]["error"].get<std::string>().find("/nonexistent/gmsh") != std::string::npos);
  CHECK(std::filesystem::exists(out / "febemesh-mesh.svg"));
  CHECK(!std::filesystem::exists(out / "gmsh-mesh.svg"));
}

TEST_CASE("compare2d --elements quad and mixed use Gmsh's recombination", "[cli][compare]") {
  if (!have_gmsh()) {
    WARN("gmsh is not installed: compare2d test skipped");
    return;
  }
  const febemesh::test::ScratchDir dir("compare_cli");
  for (const std::string kind : {"quad", "mixed"}) {
    INFO(kind);
    const auto out = dir.path() / kind;
    REQUIRE(run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR + "/examples/flange.json' -o '" +
                       out.string() + "' --level 4 --quiet --elements " + kind) == 0);
    std::ifstream in(out / "comparison.json");
    const auto j = nlohmann::json::parse(in);
    for (const char* tool : {"febemesh", "gmsh"}) {
      INFO(tool);
      REQUIRE(j[tool]["ok"] == true);
      const auto n = j[tool]["elements"].get<std::size_t>(), quads = j[tool]["quads"].get<std::size_t>();
      if (kind == "quad")
        CHECK(quads == n);
      else
        CHECK(quads > n / 2);  // quad-dominant (ours keeps triangle fans; Blossom may pair everything)
      CHECK(j[tool]["min_angle_deg"].get<double>() > 0.0);
      CHECK(j[tool]["area_rel_error"].get<double>() < 0.02);
    }
    const double ours = j["febemesh"]["elements"].get<double>(), gmsh = j["gmsh"]["elements"].get<double>();
    CHECK(std::abs(gmsh - ours) <= 0.2 * ours);
    std::ifstream geo(out / "gmsh.geo");
    std::stringstream ss;
    ss << geo.rdbuf();
    CHECK(ss.str().find("Mesh.RecombineAll = 1;") != std::string::npos);
    CHECK((ss.str().find("Mesh.SubdivisionAlgorithm = 1;") != std::string::npos) == (kind == "quad"));
  }
}

TEST_CASE("compare2d refuses bad usage and bad input", "[cli][compare]") {
  const febemesh::test::ScratchDir dir("compare_cli");
  const std::string never = (dir.path() / "never").string();
  CHECK(run_status("compare2d") == 2);
  CHECK(run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR +
                   "/examples/flange.json' -o '" + never + "' --elements hex") == 2);
  CHECK(run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR + "/examples/flange.json'") == 2);
  CHECK(run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR +
                   "/examples/flange.json' -o '" + never + "' --level 6 --size 0.1") == 2);
  CHECK(run_status(std::string("compare2d '") + FEBEMESH_SOURCE_DIR +
                   "/examples/flange.json' -o '" + never + "' --size 1e-9") == 2);  // past level 20
  CHECK(run_status("compare2d /nonexistent.json -o '" + never + "'") == 1);
  CHECK(!std::filesystem::exists(never));
}
