#include "dim2/loop_geometry.hpp"

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "dim2/bezier.hpp"

namespace febemesh::dim2 {

double wrap_parameter(const Loop& loop, double t) {
  const double n = double(loop.n_pieces());
  double w = std::fmod(t, n);
  if (w < 0.0) w += n;
  if (w >= n) w = 0.0;  // fmod of a tiny negative number rounds up to n
  return w;
}

std::pair<std::size_t, double> locate(const Loop& loop, double t) {
  MESH_ASSERT(loop.n_pieces() > 0, "empty loop");
  const double w = wrap_parameter(loop, t);
  const auto i = std::min(static_cast<std::size_t>(w), loop.n_pieces() - 1);
  return {i, std::min(1.0, w - double(i))};
}

P2 evaluate(const Loop& loop, double t) {
  const auto [i, u] = locate(loop, t);
  return bezier_point(loop.pieces[i], u);
}

P2 derivative(const Loop& loop, double t) {
  const auto [i, u] = locate(loop, t);
  return bezier_derivative(loop.pieces[i], u);
}

P2 second_derivative(const Loop& loop, double t) {
  const auto [i, u] = locate(loop, t);
  return bezier_second_derivative(loop.pieces[i], u);
}

P2 tangent(const Loop& loop, double t) {
  const auto [i, u] = locate(loop, t);
  const Bezier& q = loop.pieces[i];
  P2 d = bezier_derivative(q, u);
  const double scale = (q[1] - q[0]).norm() + (q[2] - q[1]).norm() + (q[3] - q[2]).norm();
  if (d.norm() <= 1e-12 * scale) d = u < 0.5 ? bezier_start_direction(q) : bezier_end_direction(q);
  const double nd = d.norm();
  return nd > 0.0 ? P2(d / nd) : P2::Zero();
}

double curvature(const Loop& loop, double t) {
  const auto [i, u] = locate(loop, t);
  return bezier_curvature(loop.pieces[i], u);
}

namespace {

constexpr double gl8_x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                             -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                             0.7966664774136267,  0.9602898564975363};
constexpr double gl8_w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                             0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                             0.2223810344533745, 0.1012285362903763};

double speed_integral(const Bezier& q, double a, double b) {
  const double h = 0.5 * (b - a), m = 0.5 * (a + b);
  double s = 0.0;
  for (int k = 0; k < 8; ++k) s += gl8_w[k] * bezier_derivative(q, m + h * gl8_x[k]).norm();
  return s * h;
}

double adaptive_length(const Bezier& q, double a, double b, double whole, double tol, int depth) {
  const double m = 0.5 * (a + b);
  const double left = speed_integral(q, a, m), right = speed_integral(q, m, b);
  if (depth == 0 || std::abs(left + right - whole) <= tol) return left + right;
  return adaptive_length(q, a, m, left, 0.5 * tol, depth - 1) +
         adaptive_length(q, m, b, right, 0.5 * tol, depth - 1);
}

}  // namespace

double piece_length(const Bezier& q, double u0, double u1) {
  if (u1 <= u0) return 0.0;
  const double whole = speed_integral(q, u0, u1);
  const double chord = (q[1] - q[0]).norm() + (q[2] - q[1]).norm() + (q[3] - q[2]).norm();
  return adaptive_length(q, u0, u1, whole, 1e-15 * chord + 1e-300, 40);
}

double length(const Loop& loop) {
  double s = 0.0;
  for (const Bezier& q : loop.pieces) s += piece_length(q);
  return s;
}

double arc_length(const Loop& loop, double t0, double t1) {
  const double n = double(loop.n_pieces());
  const double a = wrap_parameter(loop, t0);
  double b = wrap_parameter(loop, t1);
  if (b < a) b += n;
  double s = 0.0;
  double t = a;
  while (t < b) {
    const double piece_start = std::floor(t);
    const double end = std::min(b, piece_start + 1.0);
    const auto i = static_cast<std::size_t>(piece_start) % loop.n_pieces();
    s += piece_length(loop.pieces[i], t - piece_start, end - piece_start);
    t = end;
  }
  return s;
}

double advance(const Loop& loop, double t, double s) {
  if (s == 0.0) return wrap_parameter(loop, t);
  const double n = double(loop.n_pieces());
  const double total = length(loop);
  if (s < 0.0) s = total - std::fmod(-s, total);
  s = std::fmod(s, total);
  // Walk whole pieces, then bisect-Newton inside the last one.
  double cur = wrap_parameter(loop, t);
  for (int guard = 0; guard < 2 * int(n) + 2; ++guard) {
    const double piece_start = std::floor(cur);
    const auto i = static_cast<std::size_t>(piece_start) % loop.n_pieces();
    const Bezier& q = loop.pieces[i];
    const double u0 = cur - piece_start;
    const double rest = piece_length(q, u0, 1.0);
    if (rest < s) {
      s -= rest;
      cur = piece_start + 1.0;
      if (cur >= n) cur -= n;
      continue;
    }
    double lo = u0, hi = 1.0, u = u0 + (1.0 - u0) * (rest > 0.0 ? s / rest : 0.0);
    for (int it = 0; it < 100 && hi - lo > 1e-16; ++it) {
      const double f = piece_length(q, u0, u) - s;
      if (f > 0.0) hi = u; else lo = u;
      const double sp = bezier_derivative(q, u).norm();
      double next = sp > 0.0 ? u - f / sp : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::abs(next - u) < 1e-16) { u = next; break; }
      u = next;
    }
    return wrap_parameter(loop, piece_start + u);
  }
  return wrap_parameter(loop, cur);
}

double signed_area(const Loop& loop) {
  if (loop.pieces.empty()) return 0.0;
  // Integrate relative to a point of the loop: exactness is unchanged, cancellation is less.
  const P2 o = loop.pieces[0][0];
  constexpr double gx[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  constexpr double gw[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double a = 0.0;
  for (const Bezier& q : loop.pieces) {
    for (int k = 0; k < 3; ++k) {
      const double u = 0.5 * (1.0 + gx[k]);
      const P2 p = bezier_point(q, u) - o;
      const P2 d = bezier_derivative(q, u);
      a += 0.5 * gw[k] * (p.x() * d.y() - p.y() * d.x());
    }
  }
  return 0.5 * a;
}

double signed_area_ref(const Loop& loop, int samples_per_piece) {
  double a = 0.0;
  P2 prev = loop.pieces.empty() ? P2::Zero() : loop.pieces[0][0];
  for (const Bezier& q : loop.pieces)
    for (int k = 1; k <= samples_per_piece; ++k) {
      const P2 p = bezier_point(q, double(k) / samples_per_piece);
      a += cross(prev, p);
      prev = p;
    }
  return 0.5 * a;
}

bool is_ccw(const Loop& loop) { return signed_area(loop) > 0.0; }

Box<2> bounding_box(const Loop& loop) {
  Box<2> box = Box<2>::empty();
  for (const Bezier& q : loop.pieces) {
    const Box<2> b = bezier_tight_box(q);
    box.expand(b.lo);
    box.expand(b.hi);
  }
  return box;
}

Loop reversed(const Loop& loop) {
  const std::size_t n = loop.n_pieces();
  Loop r;
  r.name = loop.name;
  r.pieces.resize(n);
  r.corner.resize(n);
  r.level.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    r.pieces[k] = bezier_reversed(loop.pieces[n - 1 - k]);
    r.corner[k] = loop.corner[(n - k) % n];
    r.level[k] = loop.level[(n - k) % n];
  }
  return r;
}

namespace {
int ray_crossings_rec(const Bezier& q, const P2& p, int depth) {
  double ylo = q[0].y(), yhi = ylo, xlo = q[0].x(), xhi = xlo;
  for (int i = 1; i < 4; ++i) {
    ylo = std::min(ylo, q[i].y()); yhi = std::max(yhi, q[i].y());
    xlo = std::min(xlo, q[i].x()); xhi = std::max(xhi, q[i].x());
  }
  if (ylo >= p.y() || yhi < p.y() || xhi <= p.x()) return 0;
  const int change = int(q[3].y() >= p.y()) - int(q[0].y() >= p.y());
  if (xlo > p.x()) return change;
  if (depth == 0) return bezier_point(q, 0.5).x() > p.x() ? change : 0;
  const auto [l, r] = bezier_split(q, 0.5);
  return ray_crossings_rec(l, p, depth - 1) + ray_crossings_rec(r, p, depth - 1);
}
}  // namespace

int ray_crossings(const Bezier& q, const P2& p) { return ray_crossings_rec(q, p, 60); }

int winding_number(const Loop& loop, const P2& p) {
  int w = 0;
  for (const Bezier& q : loop.pieces) w += ray_crossings(q, p);
  return w;
}

}  // namespace febemesh::dim2
