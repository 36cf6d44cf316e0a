// SVG reader: path grammar, transforms, fill rules, exact Bezier conversion, and the shared glyph
// data, whose area is checked against an independent computation from the raw path data.

#include <catch2/catch.hpp>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>

#include "core/error.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/read_svg.hpp"
#include "dim2/svg_path.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double domain_area(const Domain& d) {
  double a = 0;
  for (const auto& l : d.loops) a += signed_area(l.pieces);
  return a;
}

P2 bez(const Bezier& b, double t) {
  const double s = 1 - t;
  return s * s * s * b[0] + 3 * s * s * t * b[1] + 3 * s * t * t * b[2] + t * t * t * b[3];
}

// ---- An independent area computation, written separately from the reader: a minimal
// interpreter of the path commands the glyphs use (M L H V C S Q T Z, absolute and relative),
// which samples every segment at n uniform parameters and sums the shoelace formula.
// The polygon area converges as c2/n^2 + c4/n^4; Richardson extrapolation removes c2.
double polygon_area_of_path(const std::string& d, int n) {
  std::vector<std::vector<std::pair<double, double>>> rings;
  std::size_t i = 0;
  auto skip = [&] {
    while (i < d.size() && (std::isspace(static_cast<unsigned char>(d[i])) || d[i] == ',')) ++i;
  };
  auto num = [&] {
    skip();
    const char* b = d.c_str() + i;
    char* e = nullptr;
    double v = std::strtod(b, &e);
    i += static_cast<std::size_t>(e - b);
    return v;
  };
  double cx = 0, cy = 0, sx = 0, sy = 0, lcx = 0, lcy = 0, lqx = 0, lqy = 0;
  char cmd = 0, prev = 0;
  auto sample = [&](auto f) {
    for (int k = 1; k <= n; ++k) rings.back().push_back(f(static_cast<double>(k) / n));
  };
  while (true) {
    skip();
    if (i >= d.size()) break;
    if (std::isalpha(static_cast<unsigned char>(d[i]))) cmd = d[i++];
    const bool rel = std::islower(static_cast<unsigned char>(cmd));
    const double ox = rel ? cx : 0, oy = rel ? cy : 0;
    const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(cmd)));
    if (up == 'M') {
      cx = num() + ox;
      cy = num() + oy;
      sx = cx;
      sy = cy;
      rings.push_back({{cx, cy}});
      cmd = rel ? 'l' : 'L';
      prev = 'M';
      continue;
    }
    if (up == 'Z') {
      cx = sx;
      cy = sy;
      prev = 'Z';
      continue;
    }
    double x0 = cx, y0 = cy;
    if (up == 'L' || up == 'H' || up == 'V') {
      double x1 = cx, y1 = cy;
      if (up == 'L') {
        x1 = num() + ox;
        y1 = num() + oy;
      } else if (up == 'H') {
        x1 = num() + ox;
      } else {
        y1 = num() + oy;
      }
      sample([&](double t) { return std::pair{x0 + t * (x1 - x0), y0 + t * (y1 - y0)}; });
      cx = x1;
      cy = y1;
    } else if (up == 'Q' || up == 'T') {
      double qx, qy;
      if (up == 'Q') {
        qx = num() + ox;
        qy = num() + oy;
      } else {
        qx = (prev == 'Q' || prev == 'T') ? 2 * cx - lqx : cx;
        qy = (prev == 'Q' || prev == 'T') ? 2 * cy - lqy : cy;
      }
      const double x1 = num() + ox, y1 = num() + oy;
      sample([&](double t) {
        const double s = 1 - t;
        return std::pair{s * s * x0 + 2 * s * t * qx + t * t * x1, s * s * y0 + 2 * s * t * qy + t * t * y1};
      });
      lqx = qx;
      lqy = qy;
      cx = x1;
      cy = y1;
    } else if (up == 'C' || up == 'S') {
      double ax, ay;
      if (up == 'C') {
        ax = num() + ox;
        ay = num() + oy;
      } else {
        ax = (prev == 'C' || prev == 'S') ? 2 * cx - lcx : cx;
        ay = (prev == 'C' || prev == 'S') ? 2 * cy - lcy : cy;
      }
      const double bx = num() + ox, by = num() + oy, x1 = num() + ox, y1 = num() + oy;
      sample([&](double t) {
        const double s = 1 - t;
        return std::pair{s * s * s * x0 + 3 * s * s * t * ax + 3 * s * t * t * bx + t * t * t * x1,
                         s * s * s * y0 + 3 * s * s * t * ay + 3 * s * t * t * by + t * t * t * y1};
      });
      lcx = bx;
      lcy = by;
      cx = x1;
      cy = y1;
    } else {
      FAIL("test interpreter: unsupported command " << cmd);
    }
    prev = up;
  }
  double total = 0;
  for (const auto& r : rings) {
    const double ox = r[0].first, oy = r[0].second;
    for (std::size_t k = 0; k < r.size(); ++k) {
      const auto& p = r[k];
      const auto& q = r[(k + 1) % r.size()];
      total += (p.first - ox) * (q.second - oy) - (q.first - ox) * (p.second - oy);
    }
  }
  return 0.5 * total;
}

double independent_area(const std::string& d) {
  const double a1 = polygon_area_of_path(d, 400), a2 = polygon_area_of_path(d, 800);
  return (4 * a2 - a1) / 3;
}

std::string path_d(const std::string& svg) {
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, std::regex(" d=\"([^\"]*)\"")));
  return m[1];
}

std::string svg_doc(const std::string& body) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\">" + body + "</svg>";
}

}  // namespace

TEST_CASE("every shared glyph reads and its area matches an independent computation", "[svg][data]") {
  const std::string dir = std::string(FEBEMESH_DATA_DIR) + "/2d";
  REQUIRE(std::filesystem::is_directory(dir));
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".svg") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() >= 8);
  double worst_rel = 0;
  for (const auto& f : files) {
    INFO(f);
    const Domain dom = read_domain(f);
    REQUIRE(!dom.loops.empty());
    const double ref = std::abs(independent_area(path_d(slurp(f))));
    const double a = domain_area(dom);
    CHECK(a > 0);  // loops oriented with the solid on their left: outer CCW, holes CW
    CHECK(std::abs(a - ref) <= 1e-9 * ref);
    int n_outer = 0;
    for (const auto& l : dom.loops) {
      if (signed_area(l.pieces) > 0) ++n_outer;
      for (std::size_t i = 0; i < l.n_pieces(); ++i) CHECK(l.pieces[i][3] == l.pieces[(i + 1) % l.n_pieces()][0]);
    }
    CHECK(n_outer == 1);  // each glyph is one component
    // the curve kernel's B-spline area (its own exact quadrature, after its own orientation)
    const CurveBoundary cb(dom);
    CHECK(std::abs(cb.area() - ref) <= 1e-9 * ref);
    worst_rel = std::max(worst_rel, std::abs(cb.area() - ref) / ref);
  }
  WARN("largest relative area difference, B-spline vs independent: " << worst_rel);
}

TEST_CASE("glyph topology: holes, corners and smooth joins", "[svg][data]") {
  const std::string dir = std::string(FEBEMESH_DATA_DIR) + "/2d/";
  auto count = [](const Domain& d, bool want_corner) {
    int c = 0;
    for (const auto& l : d.loops)
      for (auto x : l.corner) c += (x != 0) == want_corner;
    return c;
  };
  const Domain eight = read_domain(dir + "DejaVuSans-U0038.svg");
  CHECK(eight.loops.size() == 3);
  const Domain a = read_domain(dir + "DejaVuSans-U0041.svg");
  CHECK(a.loops.size() == 2);
  CHECK(count(a, false) == 0);  // a polygon: every join a corner
  CHECK(count(a, true) == 11);
  const Domain o = read_domain(dir + "DejaVuSans-U004F.svg");
  CHECK(o.loops.size() == 2);
  CHECK(count(o, true) == 0);  // TrueType implied on-curve points are tangent-continuous
  // mesh coordinates are (x, -y): the glyph 'A' spans y in [-1503, -10]
  Box<2> box = Box<2>::empty();
  for (const auto& l : a.loops)
    for (const auto& b : l.pieces)
      for (const auto& p : b) box.expand(p);
  CHECK(box.lo.x() == 10);
  CHECK(box.hi.x() == 1378);
  CHECK(box.lo.y() == -1503);
  CHECK(box.hi.y() == -10);
}

TEST_CASE("path data grammar", "[svg][path]") {
  SECTION("compact numbers, exponents and implicit repeats") {
    auto sp = parse_path_data("M0,0L10-.5.5.5 1.5e1 2E0h-1v-2.5e-1zm1 1 2 2");
    REQUIRE(sp.size() == 2);
    REQUIRE(sp[0].segments.size() == 5);
    CHECK(sp[0].segments[0].p[3] == P2(10, -0.5));
    CHECK(sp[0].segments[1].p[3] == P2(0.5, 0.5));
    CHECK(sp[0].segments[2].p[3] == P2(15, 2));
    CHECK(sp[0].segments[3].p[3] == P2(14, 2));
    CHECK(sp[0].segments[4].p[3] == P2(14, 1.75));
    CHECK(sp[0].closed);
    // after z the current point is the subpath start; m is relative to it, its repeat a lineto
    REQUIRE(sp[1].segments.size() == 1);
    CHECK(sp[1].segments[0].p[0] == P2(1, 1));
    CHECK(sp[1].segments[0].p[3] == P2(3, 3));
  }
  SECTION("smooth curveto reflects the previous control point") {
    auto sp = parse_path_data("M0 0C1 1 2 1 3 0S5-1 6 0Q7 1 8 0T10 0t2 0");
    const auto& s = sp[0].segments;
    REQUIRE(s.size() == 5);
    CHECK(s[1].p[1] == P2(4, -1));
    CHECK(s[3].p[1] == P2(9, -1));
    CHECK(s[4].p[1] == P2(11, 1));
    CHECK(s[4].p[3] == P2(12, 0));
  }
  SECTION("arc flags need no separators") {
    auto sp = parse_path_data("M0 0a5 5 0 1010 0");
    REQUIRE(sp[0].segments.size() == 1);
    CHECK(sp[0].segments[0].large_arc);
    CHECK(!sp[0].segments[0].sweep);
    CHECK(sp[0].segments[0].p[3] == P2(10, 0));
  }
  SECTION("errors carry the offset") {
    auto offset_of = [](const char* d) {
      try {
        parse_path_data(d);
      } catch (const PathDataError& e) {
        return static_cast<long>(e.offset());
      }
      return -1L;
    };
    CHECK(offset_of("M 0 0 L 10") == 10);      // truncated
    CHECK(offset_of("M 0 0 L nan 1") == 8);    // not finite
    CHECK(offset_of("M 0 0 L 1e400 1") == 8);  // overflows
    CHECK(offset_of("M 0 0 L 2e15 1") == 8);   // too large
    CHECK(offset_of("L 0 0") == 0);            // must start with a moveto
    CHECK(offset_of("M 0 0 X 1 1") == 6);      // unknown command
    CHECK(offset_of("M 0 0 A 1 1 0 2 0 1 1") == 14);
    CHECK(offset_of("M 0 0 L 1 1 Z 3") == 14);
  }
}

TEST_CASE("quadratics and lines become cubics exactly", "[svg][path]") {
  const P2 a(1, 2), c(4, 7), b(9, -3);
  const Bezier q = elevate_quadratic(a, c, b);
  for (double t : {0.0, 0.1, 0.37, 0.5, 0.9, 1.0}) {
    const P2 exact = (1 - t) * (1 - t) * a + 2 * t * (1 - t) * c + t * t * b;
    CHECK((bez(q, t) - exact).norm() <= 1e-14 * 10);
  }
  const Bezier l = straight_cubic(a, b);
  for (double t : {0.0, 0.25, 0.5, 1.0}) CHECK((bez(l, t) - (a + t * (b - a))).norm() <= 1e-14 * 10);
}

TEST_CASE("arcs are approximated within 1e-9 of the drawing size", "[svg][arc]") {
  const double r = 37.5;
  const Domain d = parse_svg(svg_doc("<path d='M 62.5 100 A 37.5 37.5 0 1 0 137.5 100 A 37.5 37.5 0 1 0 62.5 100 Z'/>"), "arc.svg");
  REQUIRE(d.loops.size() == 1);
  const double size = 2 * r;  // the reader measures the drawing by its control points: the diameter
  double worst = 0;
  for (const auto& b : d.loops[0].pieces)
    for (int k = 0; k <= 50; ++k) worst = std::max(worst, std::abs((bez(b, k / 50.0) - P2(100, -100)).norm() - r));
  CHECK(worst <= 1e-9 * size);
  CHECK(worst > 0);  // it is an approximation, so the check above is not vacuous
  CHECK(std::abs(domain_area(d) - std::numbers::pi * r * r) <= 1e-8 * std::numbers::pi * r * r);

  // the bound used to split arcs does bound the real error
  for (double sweep : {0.01, 0.3, 1.0, std::numbers::pi / 2}) {
    const double k = 4.0 / 3.0 * std::tan(sweep / 4);
    const Bezier b{P2(1, 0), P2(1, k), P2(std::cos(sweep) + k * std::sin(sweep), std::sin(sweep) - k * std::cos(sweep)),
                   P2(std::cos(sweep), std::sin(sweep))};
    double e = 0;
    for (int i = 0; i <= 2000; ++i) e = std::max(e, std::abs(bez(b, i / 2000.0).norm() - 1));
    CHECK(e <= arc_radial_error_bound(sweep) + 1e-15);
    CHECK(e >= 0.4 * arc_radial_error_bound(sweep) - 1e-15);
  }
}

TEST_CASE("basic shapes", "[svg][shapes]") {
  const double pi = std::numbers::pi;
  CHECK(std::abs(domain_area(parse_svg(svg_doc("<circle cx='5' cy='5' r='2'/>"), "c.svg")) - pi * 4) <= 1e-8 * pi * 4);
  CHECK(std::abs(domain_area(parse_svg(svg_doc("<ellipse cx='5' cy='5' rx='3' ry='1'/>"), "e.svg")) - pi * 3) <= 1e-8 * pi * 3);
  CHECK(domain_area(parse_svg(svg_doc("<rect x='1' y='2' width='3' height='4'/>"), "r.svg")) == Approx(12).epsilon(1e-15));
  const double rounded = 6 * 4 - (4 - pi) * 1;  // four quarter-circle corners of radius 1 cut away
  CHECK(std::abs(domain_area(parse_svg(svg_doc("<rect width='6' height='4' rx='1'/>"), "r.svg")) - rounded) <= 1e-8 * rounded);
  CHECK(domain_area(parse_svg(svg_doc("<polygon points='0,0 4,0 4,3'/>"), "p.svg")) == Approx(6));
  CHECK(domain_area(parse_svg(svg_doc("<polyline points='0 0 4 0 4 3'/>"), "p.svg")) == Approx(6));
}

TEST_CASE("transforms on elements and nested groups", "[svg][transform]") {
  auto corners = [](const Domain& d) {
    std::vector<P2> v;
    for (const auto& b : d.loops.at(0).pieces) v.push_back(b[0]);
    return v;
  };
  auto has = [](const std::vector<P2>& v, P2 p) {
    return std::any_of(v.begin(), v.end(), [&](const P2& q) { return (q - p).norm() < 1e-12; });
  };
  const Domain d = parse_svg(svg_doc("<g transform='translate(10,20)'><g transform='scale(2 3)'>"
                                     "<path transform='rotate(90)' d='M0 0H1V1H0Z'/></g></g>"),
                             "t.svg");
  const auto v = corners(d);
  // rotate(90): (1,0)->(0,1), (1,1)->(-1,1); scale (2,3); translate; then mesh (x, -y)
  CHECK(has(v, P2(10, -20)));
  CHECK(has(v, P2(10, -23)));
  CHECK(has(v, P2(8, -23)));
  CHECK(has(v, P2(8, -20)));
  CHECK(domain_area(d) == Approx(6));

  const Affine m = parse_transform("matrix(1 2 3 4 5 6)");
  CHECK((m(P2(1, 1)) - P2(1 + 3 + 5, 2 + 4 + 6)).norm() == 0);
  const Affine s = parse_transform("skewX(45) , skewY(45)");
  CHECK((s(P2(0, 1)) - P2(1, 1)).norm() < 1e-15);  // skewY first: (0,1) -> (0,1); skewX: (1,1)
  const Affine r = parse_transform("rotate(180 1 1)");
  CHECK((r(P2(0, 0)) - P2(2, 2)).norm() < 1e-14);
  CHECK_THROWS_AS(parse_transform("scale(0)"), PathDataError);
  CHECK_THROWS_AS(parse_transform("wobble(1)"), PathDataError);
  CHECK_THROWS_AS(parse_transform("translate(1 2 3)"), PathDataError);
}

TEST_CASE("fill rules decide what is solid", "[svg][fill]") {
  const std::string same = "M0 0H10V10H0ZM2 2H8V8H2Z";    // both clockwise on screen
  const std::string opposite = "M0 0H10V10H0ZM2 2V8H8V2Z";  // inner drawn the other way
  auto read = [](const std::string& d, const char* rule) {
    return parse_svg(svg_doc("<path fill-rule='" + std::string(rule) + "' d='" + d + "'/>"), "f.svg");
  };
  const Domain nz_same = read(same, "nonzero");
  CHECK(nz_same.loops.size() == 1);  // winding 2 inside: the inner square bounds nothing
  CHECK(domain_area(nz_same) == Approx(100));
  const Domain eo_same = read(same, "evenodd");
  CHECK(eo_same.loops.size() == 2);
  CHECK(domain_area(eo_same) == Approx(64));
  CHECK(domain_area(read(opposite, "nonzero")) == Approx(64));
  CHECK(domain_area(read(opposite, "evenodd")) == Approx(64));
  // inherited from a group and set by style
  const Domain g = parse_svg(svg_doc("<g style='fill:black; fill-rule: evenodd'><path d='" + same + "'/></g>"), "f.svg");
  CHECK(domain_area(g) == Approx(64));
  // three nested squares, evenodd: ring plus island
  const Domain three = read(same + "M4 4H6V6H4Z", "evenodd");
  CHECK(three.loops.size() == 3);
  CHECK(domain_area(three) == Approx(100 - 36 + 4));
  // separate elements paint their union: a circle on a plate adds nothing, an island in a hole does
  const Domain onto = parse_svg(svg_doc("<rect width='10' height='10'/><circle cx='5' cy='5' r='2'/>"), "u.svg");
  CHECK(onto.loops.size() == 1);
  CHECK(domain_area(onto) == Approx(100));
  const Domain island = parse_svg(svg_doc("<path fill-rule='evenodd' d='" + same + "'/><rect x='4' y='4' width='2' height='2'/>"), "u.svg");
  CHECK(island.loops.size() == 3);
  CHECK(domain_area(island) == Approx(100 - 36 + 4));
}

TEST_CASE("unrendered containers are ignored", "[svg]") {
  const Domain d = parse_svg(svg_doc("<defs><rect width='100' height='100'/></defs><!-- c --><rect width='1' height='1'/>"), "d.svg");
  CHECK(d.loops.size() == 1);
  CHECK(domain_area(d) == Approx(1));
}

#include "bad_input_check.hpp"

TEST_CASE("bad SVG inputs are refused with file, place and reason", "[svg][bad]") {
  const test::BadInput cases[] = {
      {"unclosed_tag.svg", "^[^ ]*:3:1: ", "does not match <path>"},
      {"truncated_path.svg", ":2:29: ", "path data ends"},
      {"nan_path.svg", ":2:19: ", "not a finite number"},
      {"overflow_path.svg", ":2:19: ", "overflows"},
      {"huge_path.svg", ":2:19: ", "1e15"},
      {"no_geometry.svg", "no_geometry.svg: ", "no geometry"},
      {"zero_area.svg", ":2:3: .*near \\(0, -?0\\)", "zero area"},
      {"tiny_loop.svg", ":2:3: rect 1, subpath 1 near \\(0, 0\\): ", "the loop is 1e-200 across, under the smallest accepted extent 1e-150"},
      // Outlines that cross: refused before the fill rules (which assume they do not) could
      // mesh one square of the two (area 100 of 112) or the rect without the circle; the place
      // in the drawing's units, y down as in the file.
      {"crossing_subpaths.svg", ":2:3: path 1, subpath 2 and path 1, subpath 1 .*at \\(10, 2\\)", "must not meet"},
      {"crossing_shapes.svg", ":3:3: circle 2, subpath 1 and rect 1, subpath 1 .*at \\(10, [28]\\)", "must not meet"},
      {"self_crossing.svg", ":2:3: path 1, subpath 1 .*at \\(6.66666667, 6.66666667\\)", "crosses or touches itself"},
      {"bad_transform.svg", ":2:32: ", "unknown transform 'shear'"},
      {"not_svg.svg", ":1:1: ", "not <svg>"},
      {"unknown_entity.svg", ":2:\\d+: ", "unknown entity"},
      {"empty.svg", ":1:1: ", "no root element"},
  };
  for (const auto& c : cases) test::check_bad_input(c);
}
