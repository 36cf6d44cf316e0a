#pragma once
// What makes a triangle surface acceptable as the boundary of a solid, as functions (STYLE.md
// §7): closed, manifold (edges and vertices), no zero-area triangles, no self-intersections,
// orientable. validate_surface() runs them in that order, throws InputError naming the file
// and the first problem with coordinates, and orients the surface outward.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dim3/aabb_tree.hpp"
#include "dim3/surface.hpp"

namespace febemesh::dim3 {

/// The coordinates validate_surface accepts: no larger in magnitude than this (as the 2D
/// readers), and a surface at least min_surface_extent across; beyond either the predicates'
/// products of lengths overflow or underflow.
inline constexpr double max_surface_coordinate = 1e15;
inline constexpr double min_surface_extent = 1e-60;

/// Edges with one triangle (holes in the surface).
std::vector<std::int32_t> boundary_edges(const Surface& s);
/// Edges with three or more triangles.
std::vector<std::int32_t> non_manifold_edges(const Surface& s);
/// Vertices whose triangles form more than one edge-connected fan (sheets touching at a point).
std::vector<std::int32_t> non_manifold_vertices(const Surface& s);
/// Triangles whose area is below 1e-12 of their longest edge squared (collinear corners).
std::vector<std::int32_t> degenerate_triangles(const Surface& s);

/// Pairs (t, u), t < u, of triangles sharing no vertex that meet, crossing or touching within
/// the orientation tolerance (triangles_intersect), ascending; candidates pruned by the tree.
std::vector<std::pair<std::int32_t, std::int32_t>> self_intersections(const Surface& s, const AabbTree& tree);
/// The same by testing all pairs (slow twin for tests).
std::vector<std::pair<std::int32_t, std::int32_t>> self_intersections_ref(const Surface& s);

/// Is every manifold edge run in opposite directions by its two triangles?
bool is_consistently_oriented(const Surface& s);
/// How many other components enclose each component (ray parity, several directions).
/// Requires a closed surface without self-intersections.
std::vector<int> nesting_depths(const Surface& s, const AabbTree& tree);

/// Makes each component consistently oriented, then flips whole components so that the signed
/// volume of each is positive at even nesting depth and negative at odd depth (cavities),
/// i.e. every normal points out of the solid. Returns the number of triangles flipped.
/// Throws InputError if a component is not orientable. `tree`, when given, is the tree of `s`
/// as it comes and is left the tree of `s` as it goes: the same object where nothing flipped,
/// else built again (a flip changes the order of a triangle's corners, so its centroid's
/// rounding and the tree may change: rebuilt, it is the tree a fresh build would make).
int orient_outward(Surface& s, const std::string& name, AabbTree* tree = nullptr);

/// The coordinates' range, every check above, then orient_outward. Throws InputError "<name>: <reason>". Returns the
/// tree of the surface as oriented, the one SurfaceBoundary would build: built once here where
/// nothing flips (three builds before: the self-intersection test, the nesting depths and
/// SurfaceBoundary; 0.14 s each at 473,088 triangles).
AabbTree validate_surface(Surface& s, const std::string& name);

}  // namespace febemesh::dim3
