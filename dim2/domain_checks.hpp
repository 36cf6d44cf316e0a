#pragma once
// Whole-input checks of a 2D domain (issue 3): there is geometry, no loop is degenerate or of
// zero area, no loop crosses or touches itself, no two loops meet. Failures are InputError
// naming Domain::source, the loops and the coordinates of the offending point.

#include <optional>
#include <vector>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// A point where the loop meets itself other than at its own junctions, if any. Points closer
/// than `tol` (mesh units) count as meeting.
std::optional<P2> loop_self_intersection(const Loop& loop, double tol);
/// A point where two different loops meet (closer than `tol`), if any.
std::optional<P2> loops_intersection(const Loop& a, const Loop& b, double tol);
/// The first two loops that meet (closer than `tol`), in the order (i, j), i < j, with where:
/// check_domain's pair check, also run by the SVG reader on every outline before its fill rules.
struct LoopsMeeting {
  std::size_t i = 0, j = 0;
  P2 at = P2::Zero();
};
std::optional<LoopsMeeting> first_loops_intersection(const std::vector<Loop>& loops, double tol);
/// Slow twin of both: any two non-adjacent chords of dense polylines (`samples` per piece)
/// that cross. Finds transversal crossings only; for tests.
std::optional<P2> polyline_intersection_ref(const Loop& a, const Loop* b, int samples = 64);

/// How many other loops contain loop i (its first point); odd = a hole. Requires the loops not
/// to intersect.
std::vector<int> nesting_depths(const std::vector<Loop>& loops);

/// The tolerance the checks use: 1e-10 of the domain's size.
double check_tolerance(const Domain& domain);
/// The same of a box's size (its largest extent): the SVG reader's check of every outline.
double check_tolerance(const Box<2>& box);

/// Throws InputError unless the domain is a valid solid description (see above).
void check_domain(const Domain& domain);

}  // namespace febemesh::dim2
