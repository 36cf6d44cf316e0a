// dim2/bezier.hpp: evaluation against the Bernstein sum, derivatives against finite differences,
// splitting, exact boxes against dense sampling, curvature of a circle.

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "dim2/bezier.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

P2 bernstein_sum(const Bezier& q, double u) {
  const double v = 1.0 - u;
  return v * v * v * q[0] + 3.0 * u * v * v * q[1] + 3.0 * u * u * v * q[2] + u * u * u * q[3];
}

Bezier random_bezier(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> c(-10.0, 10.0);
  Bezier q;
  for (P2& p : q) p = P2(c(rng), c(rng));
  return q;
}

}  // namespace

TEST_CASE("evaluation matches the Bernstein sum and the power form", "[bezier]") {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 200; ++i) {
    const Bezier q = random_bezier(rng);
    const CubicPoly poly(q);
    for (double u : {0.0, 0.1, 0.37, 0.5, 0.93, 1.0}) {
      CHECK((bezier_point(q, u) - bernstein_sum(q, u)).norm() < 1e-13);
      CHECK((poly.point(u) - bernstein_sum(q, u)).norm() < 1e-13);
      CHECK((poly.d1(u) - bezier_derivative(q, u)).norm() < 1e-12);
      CHECK((poly.d2(u) - bezier_second_derivative(q, u)).norm() < 1e-12);
    }
    CHECK(bezier_point(q, 0.0) == q[0]);
    CHECK(bezier_point(q, 1.0) == q[3]);
  }
}

TEST_CASE("derivatives match central differences", "[bezier]") {
  std::mt19937_64 rng(2);
  const double h = 1e-5;
  for (int i = 0; i < 100; ++i) {
    const Bezier q = random_bezier(rng);
    for (double u : {0.2, 0.5, 0.8}) {
      const P2 fd1 = (bezier_point(q, u + h) - bezier_point(q, u - h)) / (2 * h);
      const P2 fd2 = (bezier_derivative(q, u + h) - bezier_derivative(q, u - h)) / (2 * h);
      CHECK((fd1 - bezier_derivative(q, u)).norm() < 1e-6 * (1 + fd1.norm()));
      CHECK((fd2 - bezier_second_derivative(q, u)).norm() < 1e-6 * (1 + fd2.norm()));
    }
  }
}

TEST_CASE("splitting reproduces the piece and shares the split point bitwise", "[bezier]") {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100; ++i) {
    const Bezier q = random_bezier(rng);
    const double s = 0.3;
    const auto [l, r] = bezier_split(q, s);
    CHECK(l[3] == r[0]);
    for (double u : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      CHECK((bezier_point(l, u) - bezier_point(q, s * u)).norm() < 1e-12);
      CHECK((bezier_point(r, u) - bezier_point(q, s + (1 - s) * u)).norm() < 1e-12);
    }
    const Bezier sub = bezier_sub(q, 0.2, 0.7);
    for (double u : {0.0, 0.5, 1.0}) CHECK((bezier_point(sub, u) - bezier_point(q, 0.2 + 0.5 * u)).norm() < 1e-12);
    const Bezier rev = bezier_reversed(q);
    CHECK((bezier_point(rev, 0.3) - bezier_point(q, 0.7)).norm() < 1e-12);
  }
}

TEST_CASE("tight box contains the sampled box and is no larger", "[bezier][property]") {
  febemesh::test::prop("tight box vs dense sampling", 200, [] {
    Bezier q;
    for (P2& p : q) p = P2(*rc::gen::inRange(-1000, 1000) / 100.0, *rc::gen::inRange(-1000, 1000) / 100.0);
    const Box<2> fast = bezier_tight_box(q), ref = bezier_tight_box_ref(q, 20000);
    // The sampled box lies inside the exact one; the exact one exceeds it by at most the
    // sampling error (speed * step^2).
    RC_ASSERT((fast.lo.array() <= ref.lo.array() + 1e-12).all());
    RC_ASSERT((fast.hi.array() >= ref.hi.array() - 1e-12).all());
    RC_ASSERT(((ref.lo - fast.lo).array().abs() < 1e-6).all());
    RC_ASSERT(((ref.hi - fast.hi).array().abs() < 1e-6).all());
    const Box<2> control = bezier_control_box(q);
    RC_ASSERT((control.lo.array() <= fast.lo.array()).all());
    RC_ASSERT((control.hi.array() >= fast.hi.array()).all());
  });
}

TEST_CASE("curvature of a Bezier quarter circle is close to 1/r", "[bezier]") {
  const double r = 2.0, k = 4.0 / 3.0 * (std::sqrt(2.0) - 1.0);
  const Bezier q{P2(r, 0), P2(r, k * r), P2(k * r, r), P2(0, r)};
  for (double u : {0.0, 0.25, 0.5, 0.75, 1.0}) CHECK(bezier_curvature(q, u) == Approx(1.0 / r).epsilon(3e-2));
  CHECK(bezier_curvature(bezier_reversed(q), 0.5) == Approx(-1.0 / r).epsilon(3e-2));
  CHECK(bezier_curvature(bezier_line(P2(0, 0), P2(1, 1)), 0.4) == 0.0);
}

TEST_CASE("directions at the ends skip coincident control points", "[bezier]") {
  const Bezier q{P2(0, 0), P2(1, 0), P2(1, 1), P2(1, 1)};  // P'(1) = 0, like a tripled knot
  CHECK(bezier_derivative(q, 1.0).norm() == 0.0);
  CHECK(bezier_end_direction(q) == P2(0, 1));
  CHECK(bezier_start_direction(q) == P2(1, 0));
  CHECK(angle_between_deg(P2(1, 0), P2(0, 1)) == Approx(90.0));
  double ex[4];
  CHECK(bezier_extrema(Bezier{P2(0, 0), P2(1, 2), P2(2, 2), P2(3, 0)}, ex) == 1);
  CHECK(ex[0] == Approx(0.5));
}
