#include "dim2/curve_model.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "dim2/bezier.hpp"

namespace febemesh::dim2 {

namespace {

std::size_t wrap(std::ptrdiff_t i, std::size_t n) {
  const auto m = static_cast<std::ptrdiff_t>(n);
  return static_cast<std::size_t>(((i % m) + m) % m);
}

/// Drop zero-length pieces (their start level moves to the next piece, which starts at the same
/// point) and set corner flags where the tangent direction jumps by more than `corner_deg`.
Loop finish_loop(std::vector<Bezier> pieces, std::vector<double> level, const std::string& name,
                 double corner_deg) {
  Loop loop;
  loop.name = name;
  const std::size_t n = pieces.size();
  double carried = no_level;
  for (std::size_t i = 0; i < n; ++i) {
    const double lv = std::max(level[i], carried);
    if (bezier_is_degenerate(pieces[i])) {
      carried = lv;
      continue;
    }
    carried = no_level;
    loop.pieces.push_back(pieces[i]);
    loop.level.push_back(lv);
  }
  if (carried != no_level && !loop.level.empty()) loop.level[0] = std::max(loop.level[0], carried);
  const std::size_t m = loop.pieces.size();
  loop.corner.assign(m, 0);
  for (std::size_t i = 0; i < m; ++i) {
    const P2 in = bezier_end_direction(loop.pieces[wrap(std::ptrdiff_t(i) - 1, m)]);
    const P2 out = bezier_start_direction(loop.pieces[i]);
    loop.corner[i] = angle_between_deg(in, out) > corner_deg ? 1 : 0;
  }
  return loop;
}

std::string coords(const P2& p) {
  std::ostringstream os;
  os.precision(17);
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

}  // namespace

std::vector<P2> expand_corners(const std::vector<ControlPoint>& cps) {
  std::vector<P2> q;
  q.reserve(3 * cps.size());
  for (const ControlPoint& c : cps)
    for (int k = 0; k < (c.corner ? 3 : 1); ++k) q.push_back(c.p);
  return q;
}

Loop loop_from_bspline(const std::vector<ControlPoint>& cps, const std::string& name) {
  for (std::size_t i = 0; i < cps.size(); ++i)
    if (!std::isfinite(cps[i].p.x()) || !std::isfinite(cps[i].p.y()))
      throw InputError(name + ": control point " + std::to_string(i) + " is not finite");
  const std::vector<P2> q = expand_corners(cps);
  // The level of a control point sits on the curve point of its knot: for a corner, the middle
  // copy (where the curve passes through the corner).
  std::vector<double> knot_level;
  for (const ControlPoint& c : cps) {
    if (c.corner) {
      knot_level.push_back(no_level);
      knot_level.push_back(c.level);
      knot_level.push_back(no_level);
    } else {
      knot_level.push_back(c.level);
    }
  }
  const std::size_t n = q.size();
  if (n == 0) return Loop{{}, {}, {}, name};
  auto Q = [&](std::ptrdiff_t i) -> const P2& { return q[wrap(i, n)]; };
  // Junction (knot) points, computed once so adjacent pieces share them bitwise; a tripled
  // point is reproduced exactly rather than as (P + 4P + P) / 6.
  std::vector<P2> junction(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = std::ptrdiff_t(i);
    junction[i] = (Q(k - 1) == Q(k) && Q(k) == Q(k + 1)) ? Q(k) : (Q(k - 1) + 4.0 * Q(k) + Q(k + 1)) / 6.0;
  }
  std::vector<Bezier> pieces(n);
  for (std::size_t i = 0; i < n; ++i) {
    const P2& b = Q(std::ptrdiff_t(i));
    const P2& c = Q(std::ptrdiff_t(i) + 1);
    const P2 b1 = b == c ? b : P2((2.0 * b + c) / 3.0);
    const P2 b2 = b == c ? b : P2((b + 2.0 * c) / 3.0);
    pieces[i] = Bezier{junction[i], b1, b2, junction[(i + 1) % n]};
  }
  // A C2 join has no tangent jump up to rounding; only a tripled knot makes one.
  return finish_loop(std::move(pieces), std::move(knot_level), name, 1e-6);
}

Loop loop_from_beziers(std::vector<Bezier> pieces, const std::string& name, double corner_angle_deg) {
  const std::size_t n = pieces.size();
  double scale = 0.0;
  for (const Bezier& b : pieces)
    for (const P2& p : b) {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
        throw InputError(name + ": control point " + coords(p) + " is not finite");
      scale = std::max(scale, p.cwiseAbs().maxCoeff());
    }
  // Joins must meet; within rounding they are made to meet bitwise.
  for (std::size_t i = 0; i < n; ++i) {
    P2& end = pieces[i][3];
    const P2& start = pieces[(i + 1) % n][0];
    if ((end - start).norm() > 1e-12 * std::max(scale, 1e-300))
      throw InputError(name + ": piece " + std::to_string(i) + " ends at " + coords(end) +
                       " but the next piece starts at " + coords(start) + " (the loop is not closed)");
    end = start;
  }
  std::vector<double> level(n, no_level);
  return finish_loop(std::move(pieces), std::move(level), name, corner_angle_deg);
}

Loop loop_from_polygon(const std::vector<P2>& vertices, const std::string& name) {
  std::vector<Bezier> pieces;
  const std::size_t n = vertices.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(vertices[i].x()) || !std::isfinite(vertices[i].y()))
      throw InputError(name + ": vertex " + std::to_string(i) + " is not finite");
    pieces.push_back(bezier_line(vertices[i], vertices[(i + 1) % n]));
  }
  std::vector<double> level(n, no_level);
  Loop loop = finish_loop(std::move(pieces), std::move(level), name, 0.0);
  std::fill(loop.corner.begin(), loop.corner.end(), 1);  // .poly semantics: every vertex a corner
  return loop;
}

P2 bspline_point_ref(const std::vector<P2>& q, double t) {
  const std::size_t n = q.size();
  const auto i = static_cast<std::ptrdiff_t>(std::min(std::floor(t), double(n) - 1.0));
  // Standard de Boor with knots k_r = r; basis r is centred on knot r + 2, i.e. control q[r + 2].
  P2 d[4];
  for (int j = 0; j < 4; ++j) d[j] = q[wrap(i - 3 + j + 2, n)];
  for (int k = 1; k <= 3; ++k)
    for (int j = 3; j >= k; --j) {
      const double r = double(i - 3 + j);
      const double alpha = (t - r) / double(4 - k);
      d[j] = (1.0 - alpha) * d[j - 1] + alpha * d[j];
    }
  return d[3];
}

}  // namespace febemesh::dim2
