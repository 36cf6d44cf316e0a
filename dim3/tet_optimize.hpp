#pragma once
// Untangling and quality optimisation of a tetrahedral mesh by moving one node at a time
// (Gauss-Seidel local search, Freitag & Knupp style): a node moves to the candidate position
// that most raises the worst quality among its tetrahedra. The quality is lexicographic: any
// tetrahedron of positive volume beats any inverted or flat one; inverted ones are ranked by
// their signed mean-ratio volume 6 sqrt(2) V / l_rms^3 (so the search untangles), positive ones
// by their smallest dihedral angle (so the same search then removes slivers).
//
// Candidates: steps along the gradient of the worst tetrahedron's quality and of the sum over
// the nearly worst ones, the centroid of the node's neighbours and halfway to it; for bad
// surface nodes at a crease also those steps and the way to their interface neighbours'
// centroid within the tangent planes around them. Surface nodes (where.patch >= 0) move too
// but every candidate is projected back onto the surface first, so they stay on it exactly;
// nodes flagged fixed (feature corners) never move. A move is accepted only if it strictly
// raises the node's worst quality, so no tetrahedron ever inverts that was not inverted, and
// the mesh's minimum never drops.

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "core/boundary.hpp"
#include "core/box.hpp"
#include "core/mesh.hpp"
#include "dim3/node_tets.hpp"

namespace febemesh::dim3 {

using SurfaceProjection = std::function<std::pair<Point<3>, BoundaryLocation>(const Point<3>&)>;

/// A point on a feature line, its location on the surface and the line's unit tangent there.
struct LineSlide {
  Point<3> point = Point<3>::Zero();
  BoundaryLocation where;
  Point<3> tangent = Point<3>::Zero();
};
/// slide(x0, w0, x): the point of the feature line through the node at x0 (location w0) near x.
using LineProjection = std::function<LineSlide(const Point<3>&, const BoundaryLocation&, const Point<3>&)>;

struct TetOptimizeOptions {
  int max_sweeps = 40;
  /// Nodes whose worst dihedral angle is at least this stay put (degrees).
  double target_dihedral_deg = 30.0;
  /// Per node: 1 = never moves. Empty = none.
  std::vector<std::uint8_t> fixed;
  /// Surface nodes are those with where[v].patch >= 0; without a projection they stay put.
  SurfaceProjection project;
  /// Per node: 1 = a feature-line node, which moves along its line only (every candidate is
  /// brought back by `slide`, and it also tries steps along the line's tangent). Empty = none;
  /// needs slide. Fixed nodes never move.
  std::vector<std::uint8_t> on_line;
  LineProjection slide;
  /// Per node: the box its moves stay in (a candidate outside it is not taken). Empty = none;
  /// an empty box (lo > hi) = unbounded.
  std::vector<Box<3>> bounds;
  /// Only untangle: stop a node as soon as its tetrahedra are all positive.
  bool untangle_only = false;
  /// With untangle_only: where the max-min candidates leave a node's tetrahedra inverted,
  /// descend Escobar et al.'s smooth untangling objective (a move that inverts no more
  /// tetrahedra and lowers it is taken even if it does not raise the worst one). Surface nodes
  /// too with escobar_surface (their descent is projected onto the surface).
  bool escobar = false;
  bool escobar_surface = false;
  /// Outward unit normal of the surface at a location. With it, the interface triangles of a
  /// surface node count among its elements: one whose normal points against the surface's
  /// (the sum at its three nodes) is folded, ranked like an inverted tetrahedron. Positive
  /// tetrahedra alone let a surface node slide over its neighbours, and the mesh then covers
  /// a strip twice.
  std::function<Point<3>(const BoundaryLocation&)> surface_normal;
  /// Surface nodes at a crease (interface neighbours' normals 30 deg or more apart) whose worst
  /// dihedral angle is below this (degrees) also try moves in the tangent planes of the surface
  /// around them (the quality pass only, not untangle_only): closest points bring the other
  /// candidates back onto a convex feature line, which nodes brought there by their projections
  /// can then never leave. Only there: for every surface node below the target, sphere966 L5
  /// went 27.67 -> 27.56 deg; below 15 deg, L4 went 28.17 -> 27.95 (at creases only: both
  /// byte-identical). The bar trades one locked place against another (CLI, min dihedral, deg):
  /// 0: spool L4 9.45, anchor L4 8.72; 10: 10.24, 8.73; 12: 11.00, 5.86; 15: 13.91, 6.84 (a
  /// bridge quad over a convex feature edge, whose nodes end worse on another path).
  double tangent_below_deg = 10.0;
  /// Threads for the sweeps (project and surface_normal must then be safe to call
  /// concurrently); the result is the same, bit for bit, for every count.
  int n_threads = 1;
  /// The tetrahedra's search ranks handed from one pass to the next (the pipeline's sweeps and
  /// edge removal rounds; EdgeRemovalOptions::ranks). In: when it holds one value a
  /// tetrahedron, tet_search_rank of each at the current points (the caller vouches for it),
  /// used instead of ranking them all again; otherwise they are ranked. Out: tet_search_rank of
  /// each at the end, the moved ones' ranked again (the sweeps' own ranks differ to rounding),
  /// so the next pass gets the numbers it would compute. Null: neither.
  std::vector<double>* ranks = nullptr;
  /// Out (when not null): the tetrahedra at each node of the mesh as it leaves, where the call
  /// listed them (it moved nodes), else cleared; for the edge removal after it
  /// (EdgeRemovalOptions::incidence).
  NodeTets* incidence = nullptr;
};

struct TetOptimizeStats {
  int sweeps = 0;
  std::size_t moves = 0;
  std::size_t inverted_before = 0, inverted_after = 0;  ///< tetrahedra
  std::size_t folded_before = 0, folded_after = 0;      ///< interface triangles (with surface_normal)
  /// The smallest dihedral angles; 0 with untangle_only (and no ranks), which does not rank
  /// the positive tetrahedra.
  double min_dihedral_before_deg = 0.0, min_dihedral_after_deg = 0.0;
};

/// Quality of one tetrahedron (a, b, c, d in Gmsh order) as used by the search: the smallest
/// dihedral angle in radians when the volume is positive (above 1e-9 of the mean-ratio scale),
/// else (signed mean ratio) - 1 <= -1.
double tet_search_quality(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d);

/// What the search compares: ordered like tet_search_quality and of the same sign, without
/// acos or roots for positive tetrahedra: 1 - c|c| in [0, 2], c the cosine of the smallest
/// dihedral angle; inverted and flat ones as tet_search_quality (<= -1).
double tet_search_rank(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d);

/// tet_search_rank where it is 0 or below; 1 for the tetrahedra whose mean ratio is above 1e-3,
/// whose tet_search_rank is above 1e-9 (what the untangling needs: which are at or below 0).
double tet_untangle_rank(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d);

/// tet_search_rank of a positive tetrahedron whose smallest dihedral angle is `angle` radians.
double tet_search_rank_of_angle(double angle);

/// Smallest dihedral angle of a tetrahedron in degrees (0 when flat); sign-free.
double tet_min_dihedral_deg(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& d);

/// Orientation of an interface triangle against the surface: the cosine between its normal and
/// `ref` (1 = aligned), -1 when it is degenerate.
double surface_alignment(const Point<3>& a, const Point<3>& b, const Point<3>& c, const Point<3>& ref);

/// Optimises mesh.points in place (the solid must be all Tet4); `where` (one per node) is
/// updated for surface nodes that move.
TetOptimizeStats optimize_tets(Mesh<3>& mesh, std::vector<BoundaryLocation>& where, const TetOptimizeOptions& opt);

}  // namespace febemesh::dim3
