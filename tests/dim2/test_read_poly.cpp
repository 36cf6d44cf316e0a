// Triangle .poly reader: loops from segments, every vertex a corner, holes checked against nesting.

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "bad_input_check.hpp"
#include "dim2/read_poly.hpp"
#include "dim2/svg_path.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {
// A 10 x 10 square with a 2 x 2 square hole; segments listed out of order, 0-based, with markers.
const char* square_with_hole = R"(# square with hole
8 2 1 1
0 0 0   0.5 1
1 10 0  0.5 1
2 10 10 0.5 1
3 0 10  0.5 1
4 4 4   0.5 2
5 6 4   0.5 2
6 6 6   0.5 2
7 4 6   0.5 2
8 1
0 0 1 1
1 5 4 2
2 1 2 1
3 6 7 2
4 2 3 1
5 7 4 2
6 3 0 1
7 5 6 2
1
0 5 5
)";
}  // namespace

TEST_CASE(".poly: loops, corners and orientation", "[poly]") {
  const Domain d = parse_poly(square_with_hole, "sq.poly");
  REQUIRE(d.loops.size() == 2);
  double total = 0;
  for (const auto& l : d.loops) {
    CHECK(std::count(l.corner.begin(), l.corner.end(), 1) == 4);
    total += signed_area(l.pieces);
  }
  CHECK(signed_area(d.loops[0].pieces) == Approx(100));  // outer counter-clockwise
  CHECK(signed_area(d.loops[1].pieces) == Approx(-4));   // hole clockwise
  CHECK(total == Approx(96));
}

TEST_CASE(".poly: vertices from the companion .node file", "[poly]") {
  const char* poly = "0 2 0 0\n3 0\n1 1 2\n2 2 3\n3 3 1\n0\n";
  const char* node = "3 2 0 0\n1 0 0\n2 3 0\n3 0 4\n";
  const Domain d = parse_poly(poly, "t.poly", node, "t.node");
  REQUIRE(d.loops.size() == 1);
  CHECK(signed_area(d.loops[0].pieces) == Approx(6));
}

TEST_CASE("bad .poly inputs are refused with file, place and reason", "[poly][bad]") {
  const test::BadInput cases[] = {
      {"open_chain.poly", "near \\(0, 0\\)", "vertex 1 has 1 segments"},
      {"hole_in_solid.poly", ":21:1: ", "lies in the solid"},
      {"unmarked_hole.poly", "near \\(4, 4\\)", "no hole point marks it"},
      {"truncated.poly", ":\\d+:\\d+: ", "file ends"},
      {"bad_number.poly", ":3:5: ", "y coordinate"},
      {"zero_length_segment.poly", ":8:3: ", "zero length"},
      {"tiny_loop.poly", "loop 1 \\(from segment 1\\): ", "the loop is 1e-200 across, under the smallest accepted extent 1e-150"},
      {"bad_index.poly", ":8:5: ", "out of range"},
  };
  for (const auto& c : cases) test::check_bad_input(c);
}
