// Native JSON reader: the documented format, the bundled examples, dispatch, and bad inputs.

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "bad_input_check.hpp"
#include "core/error.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/read_native.hpp"
#include "dim2/svg_path.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

double domain_area(const Domain& d) {
  double a = 0;
  for (const auto& l : d.loops) a += std::abs(signed_area(l.pieces)) * (signed_area(l.pieces) > 0 ? 1 : -1);
  return a;
}

std::string example(const char* name) { return std::string(FEBEMESH_SOURCE_DIR) + "/examples/" + name; }

}  // namespace

TEST_CASE("native format: loops, corners, levels, interior points and options", "[native]") {
  const std::string text = R"({
    "comment": "a 2 x 1 rectangle with a level on one corner",
    "loops": [ {"name": "box", "points": [
        {"x": 0, "y": 0, "corner": true, "level": 6},
        {"x": 2, "y": 0, "corner": true},
        {"x": 2, "y": 1, "corner": true},
        {"x": 0, "y": 1, "corner": true}]} ],
    "interior": [ {"x": 1, "y": 0.5, "level": 7, "radius": 0.25} ],
    "options": {"level": 4, "elements": "quad"}
  })";
  NativeOptions opt;
  const Domain d = parse_native(text, "box.json", &opt);
  REQUIRE(d.loops.size() == 1);
  CHECK(d.loops[0].name == "box");
  // all corners: straight pieces whose only tangent jumps are at the four vertices
  CHECK(std::abs(signed_area(d.loops[0].pieces)) == Approx(2.0).epsilon(1e-14));
  CHECK(std::count(d.loops[0].corner.begin(), d.loops[0].corner.end(), 1) == 4);
  CHECK(std::count(d.loops[0].level.begin(), d.loops[0].level.end(), 6.0) >= 1);
  REQUIRE(d.interior.size() == 1);
  CHECK(d.interior[0].p == P2(1, 0.5));
  CHECK(d.interior[0].level == 7);
  CHECK(d.interior[0].radius == 0.25);
  CHECK(d.default_level == 4);
  CHECK(opt.elements == std::optional<std::string>("quad"));
  CHECK(d.source == "box.json");
}

TEST_CASE("native smooth points give a C2 curve inside the control polygon", "[native]") {
  const Domain d = parse_native(R"({"loops": [{"points": [{"x":0,"y":0},{"x":1,"y":0},{"x":1,"y":1},{"x":0,"y":1}]}]})", "s.json");
  REQUIRE(d.loops.size() == 1);
  for (auto c : d.loops[0].corner) CHECK(!c);
  const double a = std::abs(signed_area(d.loops[0].pieces));
  CHECK(a > 0.5);
  CHECK(a < 1.0);  // a B-spline lies inside its control polygon's hull
}

TEST_CASE("bundled examples read", "[native][examples]") {
  struct Case {
    const char* file;
    std::size_t loops;
    double min_area, max_area;
  };
  // bracket: 6 x 1 base + 1.5 x ~4.2 upright - holes; flange: 36 - 4(1 - pi/4)0.64 - bore - bolt holes
  const Case cases[] = {{"bracket.json", 4, 10.0, 13.0}, {"flange.json", 6, 24.0, 30.0}, {"naca0012.json", 1, 0.080, 0.083}};
  for (const auto& c : cases) {
    INFO(c.file);
    const Domain d = read_domain(example(c.file));
    CHECK(d.loops.size() == c.loops);
    double total = 0;
    for (const auto& l : d.loops) total += std::abs(signed_area(l.pieces));
    // outline minus holes: holes are the loops after the first here
    double solid = std::abs(signed_area(d.loops[0].pieces));
    for (std::size_t i = 1; i < d.loops.size(); ++i) solid -= std::abs(signed_area(d.loops[i].pieces));
    CHECK(solid > c.min_area);
    CHECK(solid < c.max_area);
    CHECK(total > 0);
  }
  // NACA 0012: area 0.6 t c^2 * integral = 0.0822 c^2 for t = 0.12 (closed trailing edge ~0.0821)
  const Domain naca = read_domain(example("naca0012.json"));
  std::size_t corners = 0;
  for (auto c : naca.loops[0].corner) corners += c != 0;
  CHECK(corners == 1);  // only the trailing edge
  (void)domain_area;
}

TEST_CASE("bad native inputs are refused with file, place and reason", "[native][bad]") {
  const test::BadInput cases[] = {
      {"malformed.json", ":3:\\d+: ", "malformed JSON"},
      {"truncated.json", ":\\d+:\\d+: ", "malformed JSON"},
      {"level_too_deep.json", "near \\(1, 0\\).*/loops/0/points/1/level", "4^30"},
      {"negative_level.json", "near \\(0, 0\\)", "negative"},
      {"unknown_key.json", ": /loops/0/points/0/corners: ", "unknown key"},
      {"no_loops.json", ": /loops: ", "no geometry"},
      {"zero_area.json", "near \\(0, 0\\)|/loops/0", "zero"},
      // 1e-200 across: its area underflowed and it read as "zero area".
      {"tiny_loop.json", "/loops/0 \\(\"sq\"\\): ", "the loop is 1e-200 across, under the smallest accepted extent 1e-150"},
      {"two_points.json", ": /loops/0/points: ", "at least 3"},
      {"string_number.json", ": /loops/0/points/0/x: ", "must be a number"},
      {"huge_number.json", ": /loops/0/points/1/x: ", "1e15"},
      {"interior_level.json", "near \\(1, 1\\).*/interior/0/level", "4^29"},
      {"bad_elements.json", ": /options/elements: ", "tri"},
      {"unknown_format.txt", "unknown_format.txt: ", "unknown input format"},
      {"does_not_exist.json", "does_not_exist.json: ", "no such file"},
  };
  for (const auto& c : cases) test::check_bad_input(c);
}

TEST_CASE("level limit message states the memory", "[native][bad]") {
  try {
    check_level(30, "x: ");
    FAIL("level 30 accepted");
  } catch (const InputError& e) {
    const std::string m = e.what();
    CHECK(m.find("4^30") != std::string::npos);
    CHECK(m.find("GB") != std::string::npos);
  }
  CHECK_NOTHROW(check_level(28, ""));
  CHECK_NOTHROW(check_level(0, ""));
  CHECK_THROWS_AS(check_level(-0.5, ""), InputError);
}
