#pragma once
// Geometric predicates on single triangles, shared by the AABB tree, the surface checks and the
// boundary: closest point with the landing region, segment crossing, triangle-triangle and
// box-triangle overlap. Orientation signs use a relative tolerance (values below
// kOrientEps * product of the lengths involved count as zero), which is what makes the
// decisions stable under round-off; callers choose what "zero" means for them.

#include <cstdint>

#include <Eigen/Geometry>  // cross products

#include "core/box.hpp"

namespace febemesh::dim3 {

using P3 = Point<3>;

inline constexpr double kOrientEps = 1e-12;

/// Sign (-1, 0, +1) of det[b-a, c-a, d-a] (> 0: d above the plane of a, b, c seen
/// counter-clockwise); 0 when smaller than the relative tolerance.
int orient3d(const P3& a, const P3& b, const P3& c, const P3& d);

/// Where a closest point lands on a triangle (a, b, c): the face, an edge (Edge0 = ab,
/// Edge1 = bc, Edge2 = ca) or a corner.
enum class TriangleRegion : std::uint8_t { Face, Edge0, Edge1, Edge2, Vertex0, Vertex1, Vertex2 };

struct TrianglePoint {
  P3 point = P3::Zero();
  double u = 0.0, v = 0.0;  ///< point = a + u (b - a) + v (c - a)
  TriangleRegion region = TriangleRegion::Face;
};

/// Closest point of the closed triangle to p (Ericson, Real-Time Collision Detection 5.1.5).
TrianglePoint closest_on_triangle(const P3& p, const P3& a, const P3& b, const P3& c);

/// Closest point of segment [a, b] to p, as the parameter t in [0, 1].
double closest_on_segment(const P3& p, const P3& a, const P3& b);

enum class Crossing : std::uint8_t { Miss, Proper, Degenerate };

/// Segment [p, q] against the closed triangle (a, b, c). Proper: crosses the interior
/// transversally with every sign clear of the tolerance. Degenerate: touches within the
/// tolerance (through an edge or vertex, an endpoint on the plane, or coplanar overlap).
Crossing segment_triangle(const P3& p, const P3& q, const P3& a, const P3& b, const P3& c);

/// The parameter s at which the line p + s (q - p) meets the closed triangle (a, b, c)
/// (Moller-Trumbore, barycentrics in [0, 1]); infinity when the line is parallel to the plane
/// or passes outside. Callers bound s themselves (a ray: s > 0; the segment: 0 < s <= 1).
double line_triangle_parameter(const P3& p, const P3& q, const P3& a, const P3& b, const P3& c);

/// Do two triangles that share no vertex meet (within the tolerance)? Non-coplanar pairs: some
/// edge of one meets the other, crossing or touching. Coplanar pairs: their closed triangles
/// overlap or touch. Touching counts: two sheets of a surface that meet, however they meet, are
/// not a valid solid boundary (two copies of a sphere mirrored about a plane cross exactly
/// through each other's edges, every contact a touch: counted as crossings only, none was found).
bool triangles_intersect(const P3 (&t1)[3], const P3 (&t2)[3]);

/// Does the closed triangle meet the closed box? (separating axis test, Akenine-Moeller)
bool box_triangle_overlap(const Box<3>& box, const P3& a, const P3& b, const P3& c);

}  // namespace febemesh::dim3
