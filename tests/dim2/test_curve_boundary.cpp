// dim2/curve_boundary.hpp: closest points against brute force, local minima, corners,
// orientation and nesting, classify consistency, segments and control levels.

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "core/orthtree.hpp"
#include "dim2/bezier.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/loop_geometry.hpp"
#include "dim2/read_domain.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

Loop square(double x0, double y0, double s, bool ccw, const std::string& name) {
  std::vector<P2> v{P2(x0, y0), P2(x0 + s, y0), P2(x0 + s, y0 + s), P2(x0, y0 + s)};
  if (!ccw) std::reverse(v.begin(), v.end());
  return loop_from_polygon(v, name);
}

/// A wavy B-spline loop with two corners, centred at c.
Loop wavy(const P2& c, double r, int n, bool ccw, const std::string& name) {
  std::vector<ControlPoint> cps;
  for (int i = 0; i < n; ++i) {
    const double th = 2.0 * M_PI * i / n;
    const double rr = r * (1.0 + 0.2 * std::sin(3.0 * th));
    cps.push_back(ControlPoint{c + rr * P2(std::cos(th), std::sin(th)), i == 0 || i == n / 2, no_level});
  }
  if (!ccw) std::reverse(cps.begin(), cps.end());
  return loop_from_bspline(cps, name);
}

/// Outer wavy loop with a square hole, plus a second component: orientations scrambled.
Domain test_domain() {
  Domain d;
  d.source = "test";
  d.loops.push_back(wavy(P2(0, 0), 2.0, 24, false, "outer"));
  d.loops.push_back(square(-0.5, -0.5, 1.0, true, "hole"));
  d.loops.push_back(square(5.0, 0.0, 1.0, false, "island"));
  return d;
}

}  // namespace

TEST_CASE("orientation and nesting are derived from the geometry", "[boundary]") {
  const CurveBoundary b(test_domain());
  REQUIRE(b.n_loops() == 3);
  CHECK_FALSE(b.is_hole(0));
  CHECK(b.is_hole(1));
  CHECK_FALSE(b.is_hole(2));
  CHECK(b.n_components() == 2);
  CHECK(b.n_holes() == 1);
  CHECK(b.signed_area(0) > 0);
  CHECK(b.signed_area(1) == Approx(-1.0).epsilon(1e-14));
  CHECK(b.signed_area(2) == Approx(1.0).epsilon(1e-14));
  CHECK(b.area() == Approx(b.signed_area(0) + b.signed_area(1) + b.signed_area(2)));
  CHECK(b.is_inside(P2(1.5, 0.1)));
  CHECK_FALSE(b.is_inside(P2(0.0, 0.0)));  // in the hole
  CHECK(b.is_inside(P2(5.5, 0.5)));
  CHECK_FALSE(b.is_inside(P2(4.0, 0.5)));
  // Island in a hole in a component: depth 2, solid again.
  Domain d;
  d.source = "nested";
  d.loops.push_back(square(0, 0, 10, false, "a"));
  d.loops.push_back(square(2, 2, 6, false, "b"));
  d.loops.push_back(square(4, 4, 2, false, "c"));
  const CurveBoundary n(d);
  CHECK(n.nesting_depth(2) == 2);
  CHECK_FALSE(n.is_hole(2));
  CHECK(n.is_inside(P2(5, 5)));
  CHECK_FALSE(n.is_inside(P2(3, 5)));
  CHECK(n.is_inside(P2(1, 5)));
  CHECK(n.area() == Approx(100 - 36 + 4));
  // Corners: every square corner is convex (90) for outer loops, reflex (270) in a hole.
  for (const CurveCorner& c : n.corners()) CHECK(c.angle_deg == Approx(n.is_hole(c.loop) ? 270.0 : 90.0));
}

TEST_CASE("closest point agrees with dense sampling", "[boundary][property]") {
  const CurveBoundary b(test_domain());
  febemesh::test::prop("closest point vs brute force", 300, [&] {
    const P2 p(*rc::gen::inRange(-4000, 8000) / 1000.0, *rc::gen::inRange(-4000, 4000) / 1000.0);
    const ClosestPoint<2> fast = b.closest_point(p);
    const ClosestPoint<2> slow = b.closest_point_ref(p, 200);
    RC_ASSERT(fast.distance <= slow.distance + 1e-12 * 6.0);
    RC_ASSERT(std::abs(fast.distance - slow.distance) <= 1e-9);
    // The reported location evaluates to the reported point.
    RC_ASSERT((b.evaluate(fast.where.patch, fast.where.param[0]) - fast.point).norm() <= 1e-13);
    RC_ASSERT(std::abs((fast.point - p).norm() - fast.distance) <= 1e-15);
  });
}

TEST_CASE("closest point at a corner is the corner, exactly", "[boundary]") {
  Domain d;
  d.source = "square";
  d.loops.push_back(square(0, 0, 1, true, "sq"));
  const CurveBoundary b(d);
  const ClosestPoint<2> c = b.closest_point(P2(1.3, 1.2));
  CHECK(c.point == P2(1, 1));
  CHECK(c.where.kind == BoundaryLocation::Kind::Corner);
  REQUIRE(c.where.feature >= 0);
  CHECK(b.corners()[std::size_t(c.where.feature)].point == P2(1, 1));
  const ClosestPoint<2> e = b.closest_point(P2(0.3, -0.2));
  CHECK(e.where.kind == BoundaryLocation::Kind::Smooth);
  CHECK((e.point - P2(0.3, 0.0)).norm() < 1e-15);
  CHECK(e.distance == Approx(0.2).epsilon(1e-14));
}

TEST_CASE("local minima are all found, ordered, and are local minima", "[boundary]") {
  Domain d;
  d.source = "ellipse";
  std::vector<ControlPoint> cps;
  for (int i = 0; i < 16; ++i) {
    const double th = 2 * M_PI * i / 16;
    cps.push_back(ControlPoint{P2(3 * std::cos(th), std::sin(th)), false, no_level});
  }
  d.loops.push_back(loop_from_bspline(cps, "ellipse"));
  const CurveBoundary b(d);
  // From the centre of an ellipse: two minima (the ends of the minor axis).
  const auto mins = b.closest_points(P2(0.0, 0.05), 10);
  REQUIRE(mins.size() == 2);
  CHECK(mins[0].distance <= mins[1].distance);
  CHECK(mins[0].point.y() > 0);
  CHECK(mins[0].distance == Approx(b.closest_point(P2(0.0, 0.05)).distance));
  // From a point on the major axis inside: the ends of the major axis are maxima, the minor
  // axis ends are minima. Every reported minimum is a local minimum along the curve.
  const P2 p(1.0, 0.2);
  const auto all = b.closest_points(p, 10);
  REQUIRE(all.size() >= 2);
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (i > 0) CHECK(all[i - 1].distance <= all[i].distance);
    const int loop = all[i].where.patch;
    const double t = all[i].where.param[0];
    for (double dt : {-1e-4, 1e-4}) CHECK((b.evaluate(loop, t + dt) - p).norm() >= all[i].distance - 1e-15);
  }
  CHECK(b.closest_points(p, 1).size() == 1);
}

TEST_CASE("classify is consistent with is_inside and the crossing test", "[boundary][property]") {
  const CurveBoundary b(test_domain());
  febemesh::test::prop("IN / OUT boxes have no crossing and all corners on their side", 300, [&] {
    const P2 c(*rc::gen::inRange(-3000, 7000) / 1000.0, *rc::gen::inRange(-3000, 3000) / 1000.0);
    const double h = *rc::gen::inRange(1, 2000) / 1000.0;
    const Box<2> box{c - P2(h, h), c + P2(h, h)};
    const Side s = b.classify(box);
    RC_ASSERT(s == b.classify_ref(box));
    if (s == Side::Partial) return;
    const P2 corners[4] = {box.lo, P2(box.hi.x(), box.lo.y()), box.hi, P2(box.lo.x(), box.hi.y())};
    for (int k = 0; k < 4; ++k) {
      RC_ASSERT(b.is_inside(corners[k]) == (s == Side::In));
      RC_ASSERT(!b.segment_touches(corners[k], corners[(k + 1) % 4]));
    }
    RC_ASSERT(b.closest_point(c).distance > h);  // the box centre is farther than the box half-size
  });
}

TEST_CASE("the tree's top-down classification equals every leaf's own", "[boundary][classify]") {
  const CurveBoundary b(test_domain());
  const ControlFn<2> control = [&](const Box<2>& box) { return std::max(b.control_level(box), 7.0); };
  const Orthtree<2> tree = balance_2to1(subdivide_by_control(b.root_box(), control));
  const std::vector<Side> sides = classify(tree, b, 1);
  CHECK(sides == classify_ref(tree, b));
  CHECK(sides == classify(tree, b, 2));
  CHECK(std::count(sides.begin(), sides.end(), Side::In) > 0);
  CHECK(std::count(sides.begin(), sides.end(), Side::Partial) > 0);
}

TEST_CASE("segments: crossing, touching, and projection segments", "[boundary]") {
  Domain d;
  d.source = "square";
  d.loops.push_back(square(0, 0, 1, true, "sq"));
  const CurveBoundary b(d);
  CHECK(b.segment_crosses(P2(0.5, 0.5), P2(1.5, 0.5)));
  CHECK_FALSE(b.segment_crosses(P2(0.2, 0.2), P2(0.8, 0.7)));
  CHECK(b.segment_touches(P2(1.0, 0.5), P2(1.5, 0.5)));      // closed: touches at its end
  CHECK_FALSE(b.segment_crosses(P2(1.0, 0.5), P2(1.5, 0.5)));  // open: the end does not count
  CHECK(b.segment_touches(P2(-1, 2), P2(2, -1)));              // through the corner (0, 1)... and (1, 0)
  CHECK(b.segment_touches(P2(1.0, -1.0), P2(1.0, 2.0)));       // along an edge
  const P2 q(0.3, 0.4);
  CHECK_FALSE(b.segment_crosses(q, b.closest_point(q).point));
}

TEST_CASE("control levels: explicit, interpolated, interior, global and automatic", "[boundary]") {
  // Explicit levels at two corners of a square, interpolated along the edges. (Level 3 at
  // least: the thickness rule puts 4 quadrants across the square, about level 2.6 here.)
  std::vector<ControlPoint> cps{{P2(0, 0), true, 3.0}, {P2(4, 0), true, 6.0}, {P2(4, 4), true, no_level},
                                {P2(0, 4), true, no_level}};
  Domain d;
  d.source = "levels";
  d.loops.push_back(loop_from_bspline(cps, "sq"));
  {
    const CurveBoundary b(d);
    CHECK_FALSE(b.is_automatic());
    CHECK(b.control_level(Box<2>{P2(1.9, 1.9), P2(2.1, 2.1)}) == 0.0);          // away from the curve
    // Linear in the parameter: near a tripled corner the speed vanishes, so a small box spans a
    // longer parameter range (u ~ (distance / 0.67)^(1/3) on the corner's first piece).
    CHECK(b.control_level(Box<2>{P2(-0.001, -0.001), P2(0.001, 0.001)}) == Approx(3.0).margin(0.2));
    CHECK(b.control_level(Box<2>{P2(3.999, -0.001), P2(4.001, 0.001)}) == Approx(6.0).margin(0.2));
    CHECK(b.control_level(Box<2>{P2(-0.1, -0.1), P2(0.1, 0.1)}) < 4.0);
    const double mid = b.control_level(Box<2>{P2(1.9, -0.1), P2(2.1, 0.1)});
    CHECK(mid > 3.0);
    CHECK(mid < 6.0);
    CHECK(b.level_at(0, 1.0) == 3.0);
  }
  d.interior.push_back(InteriorControl{P2(2, 2), 7.0, 0.5});
  {
    CurveBoundary b(d);
    CHECK(b.control_level(Box<2>{P2(2.4, 2.0), P2(2.6, 2.1)}) == 7.0);
    CHECK(b.control_level(Box<2>{P2(2.6, 2.0), P2(2.7, 2.1)}) == 0.0);
    b.set_global_level(3.0);
    CHECK(b.control_level(Box<2>{P2(2.6, 2.0), P2(2.7, 2.1)}) == 3.0);
  }
  // Automatic: a circle wants curvature refinement; a thin slot wants more.
  Domain c;
  c.source = "auto";
  std::vector<ControlPoint> circle;
  for (int i = 0; i < 32; ++i)
    circle.push_back(ControlPoint{P2(std::cos(2 * M_PI * i / 32), std::sin(2 * M_PI * i / 32)), false, no_level});
  c.loops.push_back(loop_from_bspline(circle, "circle"));
  const CurveBoundary cb(c);
  REQUIRE(cb.is_automatic());
  const double side = cb.root_box().extent().x();
  CHECK(cb.root_box().extent().x() == Approx(cb.root_box().extent().y()));
  const double on_curve = cb.control_level(Box<2>{P2(0.95, -0.05), P2(1.05, 0.05)});
  CHECK(on_curve >= std::ceil(std::log2(side / 0.3)) - 1);
  CHECK(side / std::pow(2.0, on_curve) <= 0.3 * 1.01);
  CHECK(cb.control_level(Box<2>{P2(-0.1, -0.1), P2(0.1, 0.1)}) == 0.0);
  Domain t;
  t.source = "slot";
  t.loops.push_back(loop_from_polygon({P2(0, 0), P2(10, 0), P2(10, 0.1), P2(0, 0.1)}, "thin"));
  CurveBoundary tb(t);
  const double thin = tb.control_level(Box<2>{P2(4.9, -0.01), P2(5.1, 0.01)});
  CHECK(tb.root_box().extent().x() / std::pow(2.0, thin) <= 0.1 / CurveBoundary::quadrants_across_feature * 1.0001);
  tb.set_max_level(4);
  CHECK(tb.control_level(Box<2>{P2(4.9, -0.01), P2(5.1, 0.01)}) == 4.0);
}

TEST_CASE("every shared 2D data file passes the checks and orients consistently", "[boundary][data]") {
  for (const char* name : {"DejaVuSans-U0038", "DejaVuSans-U0041", "DejaVuSans-U0042", "DejaVuSans-U004F",
                           "DejaVuSans-U0065", "DejaVuSerif-Bold-U0052", "NimbusSans-Regular-U0061",
                           "NimbusSans-Regular-U0067"}) {
    INFO(name);
    const CurveBoundary b(read_domain(std::string(FEBEMESH_DATA_DIR) + "/2d/" + name + ".svg"));
    CHECK(b.area() > 0.0);
    double sum = 0.0;
    for (int i = 0; i < b.n_loops(); ++i) {
      CHECK((b.signed_area(i) > 0) == !b.is_hole(i));
      sum += b.signed_area(i);
    }
    CHECK(b.area() == Approx(sum));
    // The closest point of a few points agrees with brute force.
    const Box<2> box = b.bounding_box();
    for (int k = 0; k < 20; ++k) {
      const P2 p = box.lo + P2((k % 5) / 4.0 * box.extent().x(), (k / 5) / 3.0 * box.extent().y());
      CHECK(b.closest_point(p).distance <= b.closest_point_ref(p, 100).distance + 1e-12 * box.extent().maxCoeff());
    }
  }
}

TEST_CASE("set_root_scale enlarges the root square; the file's levels keep their quadrant sizes", "[boundary][size]") {
  Domain d;
  d.loops.push_back(square(0.0, 0.0, 2.0, true, "outer"));
  d.interior.push_back({P2(1.0, 1.0), 6.0, 0.1});  // level 6 within 0.1 of the centre
  CurveBoundary c(d);
  const Box<2> root = c.root_box();
  CHECK(c.root_scale() == 1.0);
  Box<2> at_centre;
  at_centre.lo = P2(0.99, 0.99);
  at_centre.hi = P2(1.01, 1.01);
  CHECK(c.control_level(at_centre) == 6.0);
  c.set_root_scale(1.5);
  CHECK(c.root_box().extent()[0] == Approx(1.5 * root.extent()[0]));
  CHECK((c.root_box().center() - root.center()).norm() < 1e-12);
  // The same quadrant size asks log2(1.5) levels more of a square 1.5x as large.
  CHECK(c.control_level(at_centre) == Approx(6.0 + std::log2(1.5)));
  c.set_root_scale(1.0);
  CHECK(c.control_level(at_centre) == 6.0);
  CHECK(c.root_box().extent()[0] == root.extent()[0]);
}
