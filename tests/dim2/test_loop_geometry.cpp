// dim2/curve_model.hpp + dim2/loop_geometry.hpp: B-spline -> Bezier conversion against de Boor,
// corners and levels, exact areas, arc length, orientation and winding numbers.

#include <catch2/catch.hpp>
#include <cmath>

#include "dim2/bezier.hpp"
#include "dim2/curve_model.hpp"
#include "dim2/loop_geometry.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

/// n cubic arcs approximating a circle (the standard 4/3 tan(theta/4) handles).
Loop bezier_circle(int n, double r, const P2& c = P2::Zero()) {
  std::vector<Bezier> pieces;
  const double h = 2.0 * M_PI / n, k = 4.0 / 3.0 * std::tan(h / 4.0);
  for (int i = 0; i < n; ++i) {
    const double a = i * h, b = (i + 1) * h;
    const P2 p0 = c + r * P2(std::cos(a), std::sin(a)), p3 = c + r * P2(std::cos(b), std::sin(b));
    pieces.push_back(Bezier{p0, p0 + k * r * P2(-std::sin(a), std::cos(a)), p3 - k * r * P2(-std::sin(b), std::cos(b)), p3});
  }
  return loop_from_beziers(pieces, "circle");
}

}  // namespace

TEST_CASE("B-spline to Bezier conversion reproduces de Boor evaluation", "[loop][property]") {
  febemesh::test::prop("Bezier form == de Boor", 100, [] {
    const int n = *rc::gen::inRange(3, 12);
    std::vector<ControlPoint> cps;
    for (int i = 0; i < n; ++i) {
      const double th = 2.0 * M_PI * i / n;
      const double r = 1.0 + *rc::gen::inRange(0, 100) / 200.0;
      cps.push_back(ControlPoint{P2(r * std::cos(th), r * std::sin(th)), *rc::gen::inRange(0, 3) == 0, no_level});
    }
    const Loop loop = loop_from_bspline(cps, "random");
    const std::vector<P2> q = expand_corners(cps);
    // Distinct control points: no piece is degenerate, so piece i is knot span i.
    RC_ASSERT(loop.n_pieces() == q.size());
    for (std::size_t i = 0; i < q.size(); ++i)
      for (double u : {0.0, 0.3, 0.5, 0.9}) {
        const double t = double(i) + u;
        RC_ASSERT((evaluate(loop, t) - bspline_point_ref(q, t)).norm() < 1e-13);
      }
    for (std::size_t i = 0; i < loop.n_pieces(); ++i) RC_ASSERT(loop.pieces[i][3] == loop.pieces[(i + 1) % loop.n_pieces()][0]);
  });
}

TEST_CASE("a tripled control point is an exact corner; simple points stay smooth", "[loop]") {
  const std::vector<ControlPoint> cps{{P2(0, 0), true, 5.0}, {P2(2, 0), false, no_level}, {P2(2, 2), false, 3.0},
                                      {P2(0, 2), false, no_level}};
  const Loop loop = loop_from_bspline(cps, "one corner");
  REQUIRE(loop.n_pieces() == 6);
  // Expanded: P0 P0 P0 P1 P2 P3: the corner is the start of piece 1 (middle copy).
  for (std::size_t i = 0; i < 6; ++i) CHECK(bool(loop.corner[i]) == (i == 1));
  CHECK(loop.pieces[1][0] == P2(0, 0));
  CHECK(loop.level[1] == 5.0);
  CHECK(loop.level[4] == 3.0);
  CHECK(loop.level[0] == no_level);
  // The tangent jumps at the corner, is continuous elsewhere.
  CHECK(angle_between_deg(bezier_end_direction(loop.pieces[0]), bezier_start_direction(loop.pieces[1])) > 45.0);
  CHECK(angle_between_deg(bezier_end_direction(loop.pieces[3]), bezier_start_direction(loop.pieces[4])) < 1e-9);
}

TEST_CASE("zero-length pieces are dropped and their level kept", "[loop]") {
  // The same corner given twice: 6 copies, so some knot spans have no extent.
  const std::vector<ControlPoint> cps{{P2(0, 0), true, no_level}, {P2(0, 0), true, 4.0}, {P2(3, 0), true, no_level},
                                      {P2(0, 3), true, no_level}};
  const Loop loop = loop_from_bspline(cps, "repeated corner");
  CHECK(loop.n_pieces() < 12);
  for (const Bezier& q : loop.pieces) CHECK_FALSE(bezier_is_degenerate(q));
  bool has_level = false;
  for (std::size_t i = 0; i < loop.n_pieces(); ++i)
    if (loop.level[i] == 4.0) has_level = loop.pieces[i][0] == P2(0, 0);
  CHECK(has_level);
  CHECK(signed_area(loop) == Approx(4.5).epsilon(1e-14));  // a triangle of straight pieces
}

TEST_CASE("a polygon's area is exact, its perimeter too", "[loop]") {
  const std::vector<P2> v{P2(0, 0), P2(4, 0), P2(4, 3), P2(2, 5), P2(0, 3)};
  const Loop loop = loop_from_polygon(v, "house");
  CHECK(loop.n_pieces() == 5);
  for (auto c : loop.corner) CHECK(c == 1);
  double shoelace = 0;
  for (std::size_t i = 0; i < v.size(); ++i) shoelace += cross(v[i], v[(i + 1) % v.size()]);
  CHECK(std::abs(signed_area(loop) - 0.5 * shoelace) < 1e-14);
  CHECK(signed_area(reversed(loop)) == Approx(-0.5 * shoelace).epsilon(1e-15));
  CHECK(length(loop) == Approx(4 + 3 + 2 * std::sqrt(8.0) + 3).epsilon(1e-14));
  CHECK(is_ccw(loop));
  const Box<2> b = bounding_box(loop);
  CHECK(b.lo == P2(0, 0));
  CHECK(b.hi == P2(4, 5));
}

TEST_CASE("circle approximations: area and length converge to pi r^2 and 2 pi r", "[loop]") {
  double prev = 1.0;
  for (int n : {4, 8, 16, 32}) {
    const Loop c = bezier_circle(n, 3.0, P2(100, -50));
    const double err = std::abs(signed_area(c) - M_PI * 9.0) / (M_PI * 9.0);
    CHECK(err < prev);
    prev = err;
    // The exact Green quadrature agrees with a fine polygon (the slow twin) to its h^2 error.
    CHECK(signed_area(c) == Approx(signed_area_ref(c, 4000)).epsilon(1e-6));
    CHECK(length(c) == Approx(2 * M_PI * 3.0).epsilon(n >= 8 ? 1e-5 : 1e-3));
  }
  CHECK(prev < 1e-8);  // 32 arcs: radial error ~ 1e-9
}

TEST_CASE("arc length is additive and advance inverts it", "[loop]") {
  const Loop c = bezier_circle(8, 1.0);
  const double total = length(c);
  CHECK(arc_length(c, 1.3, 5.7) + arc_length(c, 5.7, 1.3) == Approx(total).epsilon(1e-13));
  CHECK(arc_length(c, 0.0, 2.0) == Approx(total / 4).epsilon(1e-13));
  for (double s : {0.1, 1.0, 3.0, -0.7}) {
    const double t = advance(c, 6.5, s);
    const double walked = s >= 0 ? arc_length(c, 6.5, t) : arc_length(c, t, 6.5);
    CHECK(walked == Approx(std::abs(s)).epsilon(1e-10));
  }
  CHECK(wrap_parameter(c, -0.5) == Approx(7.5));
}

TEST_CASE("winding numbers and tangents", "[loop]") {
  const Loop c = bezier_circle(6, 1.0);
  CHECK(winding_number(c, P2(0, 0)) == 1);
  CHECK(winding_number(c, P2(0.99, 0.0)) == 1);
  CHECK(winding_number(c, P2(1.01, 0.0)) == 0);
  CHECK(winding_number(c, P2(0.0, 1.5)) == 0);
  CHECK(winding_number(reversed(c), P2(0.2, 0.1)) == -1);
  // The ray through a junction point counts once.
  CHECK(winding_number(c, P2(-0.5, 0.0)) == 1);
  CHECK((tangent(c, 0.0) - P2(0, 1)).norm() < 1e-12);
  CHECK(curvature(c, 2.5) == Approx(1.0).epsilon(3e-3));
}

TEST_CASE("open Bezier chains are refused with coordinates", "[loop]") {
  std::vector<Bezier> open{bezier_line(P2(0, 0), P2(1, 0)), bezier_line(P2(1, 0), P2(0, 1))};
  CHECK_THROWS_WITH(loop_from_beziers(open, "open"), Catch::Contains("(0, 1)"));
}
