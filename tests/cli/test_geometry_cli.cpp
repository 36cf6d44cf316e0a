// `febemesh geometry` end to end: runs the built program, checks its JSON, exit codes and --svg.

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "scratch_dir.hpp"

namespace {

struct Run {
  int status = -1;
  std::string out;
};

/// Runs FEBEMESH_CLI with `args`, capturing stdout (stderr to `err_file` when given).
Run run(const std::string& args, const std::string& err_file = "/dev/null") {
  const std::string cmd = std::string("'") + FEBEMESH_CLI + "' " + args + " 2>" + err_file;
  Run r;
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char buf[4096];
  std::size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("geometry prints the loops of a native example", "[cli][geometry]") {
  const Run r = run(std::string("geometry '") + FEBEMESH_SOURCE_DIR + "/examples/flange.json'");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["components"] == 1);
  CHECK(j["holes"] == 5);
  REQUIRE(j["loops"].size() == 6);
  double sum = 0;
  for (const auto& l : j["loops"]) {
    sum += l["signed_area"].get<double>();
    CHECK((l["signed_area"].get<double>() < 0) == l["hole"].get<bool>());
    CHECK(l["length"].get<double>() > 0);
    CHECK(l["pieces"].get<int>() > 0);
  }
  CHECK(j["area"].get<double>() == Approx(sum).epsilon(1e-12));
  CHECK(j["area"].get<double>() > 24);
  CHECK(j["area"].get<double>() < 30);
  CHECK(j["corners"] == 4);  // the keyway
  const auto& b = j["bbox"];
  CHECK(b[0].get<double>() == Approx(-3).margin(1e-9));
  CHECK(b[2].get<double>() == Approx(3).margin(1e-9));
  CHECK(j["source"].get<std::string>().find("flange.json") != std::string::npos);
}

TEST_CASE("geometry of a shared glyph and its drawing", "[cli][geometry]") {
  const febemesh::test::ScratchDir dir("geometry_cli");
  const std::string svg = (dir.path() / "eight.svg").string();
  const Run r = run(std::string("geometry '") + FEBEMESH_DATA_DIR + "/2d/DejaVuSans-U0038.svg' --svg '" + svg + "'");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["components"] == 1);
  CHECK(j["holes"] == 2);
  CHECK(j["area"].get<double>() > 0);
  // the glyph is drawn in mesh coordinates (x, -y): its bbox lies below the x axis
  CHECK(j["bbox"][3].get<double>() <= -10 + 1e-9);
  REQUIRE(std::filesystem::exists(svg));
  const std::string drawing = slurp(svg);
  CHECK(drawing.rfind("<svg", 0) == 0);
  CHECK(drawing.find(" C") != std::string::npos);       // the loops as cubic pieces
  CHECK(drawing.find("control polygon") != std::string::npos);
  CHECK(drawing.find("</svg>") != std::string::npos);
  // same input, same output byte for byte
  const std::string svg2 = (dir.path() / "eight2.svg").string();
  const Run r2 = run(std::string("geometry '") + FEBEMESH_DATA_DIR + "/2d/DejaVuSans-U0038.svg' --svg '" + svg2 + "'");
  CHECK(r2.out == r.out);
  CHECK(slurp(svg2) == drawing);
}

TEST_CASE("geometry exit codes: bad input 1 with a message, bad usage 2", "[cli][geometry]") {
  const febemesh::test::ScratchDir scratch("geometry_cli");
  const std::string dir = scratch.path().string();
  const std::string err = dir + "/err.txt";
  const std::string svg = dir + "/never.svg";
  const std::string bad = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim2/bad_inputs/nan_path.svg";
  const Run r = run("geometry '" + bad + "' --svg '" + svg + "'", err);
  CHECK(r.status == 1);
  CHECK(r.out.empty());
  CHECK(!std::filesystem::exists(svg));  // nothing written on failure
  const std::string msg = slurp(err);
  CHECK(msg.find("nan_path.svg:2:19:") != std::string::npos);

  CHECK(run("geometry '" + dir + "/missing.json'").status == 1);
  CHECK(run(std::string("geometry '") + FEBEMESH_SOURCE_DIR + "/tests/dim2/bad_inputs/level_too_deep.json'").status == 1);
  CHECK(run("geometry --frobnicate x.json").status == 2);
  CHECK(run("geometry").status == 2);
  CHECK(run("geometry a.json b.json").status == 2);
  const Run help = run("geometry --help");
  CHECK(help.status == 0);
  CHECK(help.out.find("usage: febemesh geometry INPUT") != std::string::npos);
}
