#pragma once
// One cubic Bezier piece of a loop: evaluation, derivatives, curvature, splitting and boxes.
// Everything the loop and boundary queries need from a single polynomial piece lives here.

#include <utility>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// The piece in power form P(u) = a + u (b + u (c + u d)): four multiply-adds per coordinate,
/// used by the hot closest-point loop (Newton needs P, P', P'' at the same u).
struct CubicPoly {
  P2 a, b, c, d;
  explicit CubicPoly(const Bezier& q);
  P2 point(double u) const { return a + u * (b + u * (c + u * d)); }
  P2 d1(double u) const { return b + u * (2.0 * c + u * (3.0 * d)); }
  P2 d2(double u) const { return 2.0 * c + u * (6.0 * d); }
};

P2 bezier_point(const Bezier& q, double u);         ///< de Casteljau, exact at u = 0 and 1
P2 bezier_derivative(const Bezier& q, double u);    ///< dP/du
P2 bezier_second_derivative(const Bezier& q, double u);
/// Signed curvature (left turn positive); 0 where the speed vanishes or the piece is straight.
double bezier_curvature(const Bezier& q, double u);

/// The two halves at u (de Casteljau); the shared point is bitwise the same in both.
std::pair<Bezier, Bezier> bezier_split(const Bezier& q, double u);
/// The sub-piece on [u0, u1] (u0 < u1), reparametrised to [0, 1].
Bezier bezier_sub(const Bezier& q, double u0, double u1);
Bezier bezier_reversed(const Bezier& q);
/// A straight piece a -> b with uniform speed.
Bezier bezier_line(const P2& a, const P2& b);

/// Box of the control points: contains the piece (convex hull property), exact arithmetic.
Box<2> bezier_control_box(const Bezier& q);
/// Tight box: endpoints plus the roots of each coordinate's derivative in (0, 1).
Box<2> bezier_tight_box(const Bezier& q);
/// Slow twin of bezier_tight_box: dense sampling (a box slightly inside the true one).
Box<2> bezier_tight_box_ref(const Bezier& q, int samples = 10000);

/// Parameters in (0, 1), ascending, where x' or y' vanishes: between them the piece is monotone
/// in both coordinates, hence cannot cross itself. Returns how many (at most 4).
int bezier_extrema(const Bezier& q, double out[4]);

/// All four control points equal: a zero-length piece.
bool bezier_is_degenerate(const Bezier& q);
/// Direction in which the piece leaves its start (first non-zero control-point difference),
/// not normalised; zero only for a degenerate piece. Also right when P'(0) = 0 (tripled knots).
P2 bezier_start_direction(const Bezier& q);
/// Direction in which the piece arrives at its end (same rule from the other side).
P2 bezier_end_direction(const Bezier& q);

/// Angle in degrees (0..180) between two directions; 0 if either is zero.
double angle_between_deg(const P2& a, const P2& b);
inline double cross(const P2& a, const P2& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace febemesh::dim2
