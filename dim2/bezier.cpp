#include "dim2/bezier.hpp"

#include <algorithm>
#include <cmath>

namespace febemesh::dim2 {

CubicPoly::CubicPoly(const Bezier& q)
    : a(q[0]),
      b(3.0 * (q[1] - q[0])),
      c(3.0 * (q[0] - 2.0 * q[1] + q[2])),
      d(q[3] - q[0] + 3.0 * (q[1] - q[2])) {}

P2 bezier_point(const Bezier& q, double u) {
  const double v = 1.0 - u;
  const P2 p01 = v * q[0] + u * q[1], p12 = v * q[1] + u * q[2], p23 = v * q[2] + u * q[3];
  const P2 p012 = v * p01 + u * p12, p123 = v * p12 + u * p23;
  if (u == 0.0) return q[0];
  if (u == 1.0) return q[3];
  return v * p012 + u * p123;
}

P2 bezier_derivative(const Bezier& q, double u) {
  const double v = 1.0 - u;
  const P2 h0 = q[1] - q[0], h1 = q[2] - q[1], h2 = q[3] - q[2];
  return 3.0 * (v * v * h0 + 2.0 * u * v * h1 + u * u * h2);
}

P2 bezier_second_derivative(const Bezier& q, double u) {
  const P2 s0 = q[2] - 2.0 * q[1] + q[0], s1 = q[3] - 2.0 * q[2] + q[1];
  return 6.0 * ((1.0 - u) * s0 + u * s1);
}

double bezier_curvature(const Bezier& q, double u) {
  const P2 d1 = bezier_derivative(q, u), d2 = bezier_second_derivative(q, u);
  const double speed = d1.norm();
  const double scale = (q[3] - q[0]).norm() + (q[1] - q[0]).norm() + (q[2] - q[3]).norm();
  // Where the speed vanishes (tripled knots) the curvature is undefined; the geometry there is
  // a straight approach to a corner, so report the straight value rather than noise / 0.
  if (!(speed > 1e-9 * scale)) return 0.0;
  return cross(d1, d2) / (speed * speed * speed);
}

std::pair<Bezier, Bezier> bezier_split(const Bezier& q, double u) {
  const double v = 1.0 - u;
  const P2 p01 = v * q[0] + u * q[1], p12 = v * q[1] + u * q[2], p23 = v * q[2] + u * q[3];
  const P2 p012 = v * p01 + u * p12, p123 = v * p12 + u * p23;
  const P2 m = v * p012 + u * p123;
  return {Bezier{q[0], p01, p012, m}, Bezier{m, p123, p23, q[3]}};
}

Bezier bezier_sub(const Bezier& q, double u0, double u1) {
  Bezier right = u0 > 0.0 ? bezier_split(q, u0).second : q;
  if (u1 >= 1.0) return right;
  const double s = (u1 - u0) / (1.0 - u0);
  return bezier_split(right, s).first;
}

Bezier bezier_reversed(const Bezier& q) { return Bezier{q[3], q[2], q[1], q[0]}; }

Bezier bezier_line(const P2& a, const P2& b) {
  return Bezier{a, (2.0 * a + b) / 3.0, (a + 2.0 * b) / 3.0, b};
}

Box<2> bezier_control_box(const Bezier& q) {
  Box<2> b{q[0], q[0]};
  for (int i = 1; i < 4; ++i) b.expand(q[i]);
  return b;
}

namespace {
/// Roots in (0, 1) of the derivative of one coordinate (a quadratic in Bernstein form).
int derivative_roots(double h0, double h1, double h2, double roots[2]) {
  const double a = h0 - 2.0 * h1 + h2, b = 2.0 * (h1 - h0), c = h0;
  int n = 0;
  auto keep = [&](double r) {
    if (r > 0.0 && r < 1.0) roots[n++] = r;
  };
  const double scale = std::abs(h0) + std::abs(h1) + std::abs(h2);
  if (std::abs(a) <= 1e-14 * scale) {
    if (b != 0.0) keep(-c / b);
    return n;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return n;
  const double sq = std::sqrt(disc);
  // Numerically stable quadratic formula.
  const double qq = -0.5 * (b + std::copysign(sq, b));
  if (qq != 0.0) keep(c / qq);
  keep(qq / a);
  return n;
}
}  // namespace

Box<2> bezier_tight_box(const Bezier& q) {
  Box<2> box{q[0], q[0]};
  box.expand(q[3]);
  for (int d = 0; d < 2; ++d) {
    double roots[2];
    const int n = derivative_roots(q[1][d] - q[0][d], q[2][d] - q[1][d], q[3][d] - q[2][d], roots);
    for (int i = 0; i < n; ++i) box.expand(bezier_point(q, roots[i]));
  }
  return box;
}

int bezier_extrema(const Bezier& q, double out[4]) {
  int n = 0;
  for (int d = 0; d < 2; ++d)
    n += derivative_roots(q[1][d] - q[0][d], q[2][d] - q[1][d], q[3][d] - q[2][d], out + n);
  std::sort(out, out + n);
  return n;
}

Box<2> bezier_tight_box_ref(const Bezier& q, int samples) {
  Box<2> box{q[0], q[0]};
  for (int i = 1; i <= samples; ++i) box.expand(bezier_point(q, double(i) / samples));
  return box;
}

bool bezier_is_degenerate(const Bezier& q) { return q[0] == q[1] && q[1] == q[2] && q[2] == q[3]; }

P2 bezier_start_direction(const Bezier& q) {
  for (int i = 1; i < 4; ++i)
    if (q[i] != q[0]) return q[i] - q[0];
  return P2::Zero();
}

P2 bezier_end_direction(const Bezier& q) {
  for (int i = 2; i >= 0; --i)
    if (q[i] != q[3]) return q[3] - q[i];
  return P2::Zero();
}

double angle_between_deg(const P2& a, const P2& b) {
  if (a == P2::Zero() || b == P2::Zero()) return 0.0;
  return std::atan2(std::abs(cross(a, b)), a.dot(b)) * 180.0 / M_PI;
}

}  // namespace febemesh::dim2
