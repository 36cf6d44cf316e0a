// dim2/domain_checks.hpp: every bad-input case throws InputError naming the source, the loops
// and the coordinates; valid domains pass; the fast intersection test agrees with polylines.

#include <catch2/catch.hpp>
#include <cmath>
#include <regex>

#include "core/error.hpp"
#include "dim2/bezier.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/domain_checks.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

Domain domain_of(std::vector<Loop> loops) {
  Domain d;
  d.source = "shape.json";
  d.loops = std::move(loops);
  return d;
}

std::string message_of(const Domain& d) {
  try {
    check_domain(d);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The first "(x, y)" in a message.
P2 coordinates_in(const std::string& msg) {
  std::smatch m;
  const std::regex re(R"(\(([-0-9.e+]+), ([-0-9.e+]+)\))");
  if (!std::regex_search(msg, m, re)) return P2(NAN, NAN);
  return P2(std::stod(m[1]), std::stod(m[2]));
}

}  // namespace

TEST_CASE("no geometry is refused", "[checks]") {
  const std::string msg = message_of(domain_of({}));
  CHECK_THAT(msg, Catch::Contains("shape.json") && Catch::Contains("no geometry"));
  CHECK_THROWS_AS(CurveBoundary(domain_of({})), InputError);
}

TEST_CASE("zero-area and degenerate loops are refused with their place", "[checks]") {
  const std::string flat = message_of(domain_of({loop_from_polygon({P2(1, 1), P2(3, 1), P2(5, 1)}, "flat")}));
  CHECK_THAT(flat, Catch::Contains("shape.json") && Catch::Contains("'flat'") && Catch::Contains("zero area"));
  CHECK(coordinates_in(flat) == P2(1, 1));
  const std::string point = message_of(domain_of({loop_from_polygon({P2(2, 2), P2(2, 2)}, "dot")}));
  CHECK_THAT(point, Catch::Contains("'dot'") && Catch::Contains("degenerate"));
}

TEST_CASE("a self-intersecting loop is refused at the crossing", "[checks]") {
  const std::string bowtie = message_of(domain_of({loop_from_polygon({P2(0, 0), P2(2, 2), P2(2, 0), P2(0, 2)}, "bowtie")}));
  CHECK_THAT(bowtie, Catch::Contains("'bowtie'") && Catch::Contains("intersects itself"));
  CHECK((coordinates_in(bowtie) - P2(1, 1)).norm() < 1e-8);
  // A single cubic with a loop of its own, closed by a straight piece.
  const Bezier curl{P2(0, 0), P2(3, 2), P2(-1, 2), P2(2, 0)};
  const std::string own = message_of(domain_of({loop_from_beziers({curl, bezier_line(P2(2, 0), P2(0, 0))}, "curl")}));
  CHECK_THAT(own, Catch::Contains("'curl'") && Catch::Contains("intersects itself"));
  CHECK(coordinates_in(own).allFinite());
  // A spike that doubles back on itself (zero-angle corner) touches along a segment.
  const std::string spike = message_of(domain_of({loop_from_polygon({P2(0, 0), P2(4, 0), P2(2, 0), P2(2, 2)}, "spike")}));
  CHECK_THAT(spike, Catch::Contains("'spike'"));
  // A vertex touching another edge.
  const std::string touch = message_of(domain_of({loop_from_polygon({P2(0, 0), P2(4, 0), P2(4, 4), P2(2, 0.0), P2(0, 4)}, "touch")}));
  CHECK_THAT(touch, Catch::Contains("intersects itself"));
  CHECK((coordinates_in(touch) - P2(2, 0)).norm() < 1e-8);
}

TEST_CASE("loops that meet are refused, naming both", "[checks]") {
  const Loop a = loop_from_polygon({P2(0, 0), P2(2, 0), P2(2, 2), P2(0, 2)}, "first");
  const Loop b = loop_from_polygon({P2(1, 1), P2(3, 1), P2(3, 3), P2(1, 3)}, "second");
  const std::string msg = message_of(domain_of({a, b}));
  CHECK_THAT(msg, Catch::Contains("'first'") && Catch::Contains("'second'") && Catch::Contains("intersect at"));
  const P2 at = coordinates_in(msg);
  CHECK(((at - P2(2, 1)).norm() < 1e-8 || (at - P2(1, 2)).norm() < 1e-8));
  // Touching from outside at one point is also refused.
  const Loop c = loop_from_polygon({P2(2, 1), P2(4, 0), P2(4, 2)}, "touching");
  CHECK_THAT(message_of(domain_of({a, c})), Catch::Contains("'touching'"));
  // Nested without contact is fine.
  const Loop inner = loop_from_polygon({P2(0.5, 0.5), P2(1.5, 0.5), P2(1.5, 1.5), P2(0.5, 1.5)}, "inner");
  CHECK(message_of(domain_of({a, inner})).empty());
}

TEST_CASE("valid smooth loops with corners pass", "[checks]") {
  std::vector<ControlPoint> cps;
  for (int i = 0; i < 12; ++i) {
    const double th = 2 * M_PI * i / 12;
    cps.push_back(ControlPoint{P2(std::cos(th), 0.5 * std::sin(th)), i % 4 == 0, no_level});
  }
  CHECK(message_of(domain_of({loop_from_bspline(cps, "ok")})).empty());
  // A sharp (10 degree) corner is not a self-intersection.
  const Loop sharp = loop_from_polygon({P2(0, 0), P2(10, 0), P2(0, 10 * std::tan(10 * M_PI / 180))}, "sharp");
  CHECK(message_of(domain_of({sharp})).empty());
}

TEST_CASE("a long leaning spike: refused where its sides come within the tolerance, else valid", "[checks]") {
  // A fuzzed .poly (tests/fuzz/regressions/poly/thin-spike-timeout.poly): sides 7.8e9 long,
  // 11 apart at the base, meeting at the tip at an angle of ~1e-9 rad, so they run within the
  // tolerance (1e-10 of the size) of each other over the last tenth: a touch.
  const Loop thin = loop_from_polygon({P2(2, 10), P2(22221104, 7771111777), P2(8, 0), P2(4, 0)}, "thin");
  const std::string msg = message_of(domain_of({thin}));
  CHECK(msg.find("intersects itself") != std::string::npos);
  // The same spike 1e5 wide at the base (tip angle ~1.3e-5 rad): only the pieces at the tip
  // come within the tolerance, and they meet at their junction: the loop is valid.
  const Loop wide = loop_from_polygon({P2(2, 100000), P2(22221104, 7771111777), P2(8, 0), P2(4, 0)}, "wide");
  CHECK(message_of(domain_of({wide})).empty());
}

TEST_CASE("self-intersection of random polygons agrees with the polyline twin", "[checks][property]") {
  febemesh::test::prop("fast == polyline reference", 300, [] {
    const int n = *rc::gen::inRange(3, 8);
    std::vector<P2> v;
    for (int i = 0; i < n; ++i) v.push_back(P2(*rc::gen::inRange(0, 1000) / 7.0, *rc::gen::inRange(0, 1000) / 7.0));
    const Loop loop = loop_from_polygon(v, "random");
    RC_PRE(loop.n_pieces() >= 3);
    const bool fast = loop_self_intersection(loop, 1e-9).has_value();
    const bool ref = polyline_intersection_ref(loop, nullptr, 1).has_value();
    // The twin sees transversal crossings only: it may miss touching vertices, never crossings.
    if (ref) RC_ASSERT(fast);
    if (fast && !ref) {
      // Then some vertex lies on another edge (or edges overlap): check that it is a touch.
      RC_ASSERT(loop_self_intersection(loop, 1e-9).has_value());
    }
  });
}
