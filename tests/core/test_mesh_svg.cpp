// core/svg_canvas.hpp: fitting, y-up flip, escaping, determinism.

#include <catch2/catch.hpp>


#include "core/svg_canvas.hpp"

using namespace febemesh;

TEST_CASE("SVG canvas flips y and fits the view", "[svg]") {
  SvgCanvas svg(200.0, 0.0);
  SvgStyle s;
  s.fill = svg_rgb(1, 0, 0);
  svg.polygon({Point<2>(0, 0), Point<2>(10, 0), Point<2>(10, 5)}, s);
  svg.dot(Point<2>(10, 5), 2.0, s);
  svg.text(Point<2>(0, 5), "a<b & c", 10.0);
  const std::string out = svg.str();
  CHECK(out == svg.str());
  CHECK(out.find("viewBox=\"0 0 200 100\"") != std::string::npos);
  // (0,0) is the lower-left corner: pixel (0, 100); (10, 5) the upper right: (200, 0).
  CHECK(out.find("points=\"0,100 200,100 200,0\"") != std::string::npos);
  CHECK(out.find("cx=\"200\" cy=\"0\" r=\"2\"") != std::string::npos);
  CHECK(out.find("a&lt;b &amp; c") != std::string::npos);
  CHECK(out.find("fill=\"#ff0000\"") != std::string::npos);
  CHECK(svg_palette(0) != svg_palette(1));
  CHECK(svg_palette(8) == svg_palette(0));
}

TEST_CASE("SVG canvas with an explicit view and a circle in mesh units", "[svg]") {
  SvgCanvas svg(100.0, 10.0);
  svg.set_view(Box<2>{Point<2>(-1, -1), Point<2>(1, 1)});
  svg.circle(Point<2>(0, 0), 0.5, SvgStyle{});
  const std::string out = svg.str();
  CHECK(out.find("cx=\"50\" cy=\"50\" r=\"20\"") != std::string::npos);
  CHECK(out.find("height=\"100\"") != std::string::npos);
}
