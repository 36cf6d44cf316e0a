#pragma once
// Geometry of one loop as a periodic curve: parameter t in [0, n_pieces), piece floor(t),
// local u = t - floor(t). Evaluation, tangents, curvature, arc length, exact signed area,
// orientation and winding numbers.

#include <cstddef>
#include <utility>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// t reduced to [0, n_pieces).
double wrap_parameter(const Loop& loop, double t);
/// (piece, u) of a parameter; u in [0, 1].
std::pair<std::size_t, double> locate(const Loop& loop, double t);

P2 evaluate(const Loop& loop, double t);
P2 derivative(const Loop& loop, double t);  ///< dP/dt; may vanish at a tripled knot
P2 second_derivative(const Loop& loop, double t);
/// Unit tangent; where dP/dt vanishes, the limit direction from the side of increasing t.
P2 tangent(const Loop& loop, double t);
double curvature(const Loop& loop, double t);  ///< signed, left turn positive

/// Arc length of piece q on [u0, u1]: adaptive Gauss-Legendre to ~1e-14 relative.
double piece_length(const Bezier& q, double u0 = 0.0, double u1 = 1.0);
double length(const Loop& loop);
/// Arc length from t0 forward to t1 (periodic: if t1 < t0 the path wraps through t = 0).
double arc_length(const Loop& loop, double t0, double t1);
/// The parameter reached by walking arc length s from t (backwards when s < 0), wrapped.
double advance(const Loop& loop, double t, double s);

/// Signed area by Green's theorem, exact: x y' is a degree-5 polynomial per piece, so the
/// 3-point Gauss rule integrates it exactly. Positive for counter-clockwise loops.
double signed_area(const Loop& loop);
/// Slow twin: shoelace formula of `samples_per_piece` points per piece (converges as h^2).
double signed_area_ref(const Loop& loop, int samples_per_piece = 2000);
bool is_ccw(const Loop& loop);

Box<2> bounding_box(const Loop& loop);  ///< tight (derivative roots per piece)
/// The same curve traversed the other way; corners and levels stay on their points.
Loop reversed(const Loop& loop);

/// Signed crossings of the ray {y = p.y, x > p.x} by piece q: +1 upward, -1 downward, with
/// "above" meaning y >= p.y so that the sum over a closed loop is exact (a winding number).
int ray_crossings(const Bezier& q, const P2& p);
/// Winding number of the loop around p (p not on the loop).
int winding_number(const Loop& loop, const P2& p);

}  // namespace febemesh::dim2
