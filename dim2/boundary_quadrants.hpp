#pragma once
// Step 3-4 of the paper, "Generation of boundary quadrants": one boundary quadrant between each
// free edge of the interior quadrants and the curve, by projecting the edge's ends onto the
// curve (closest point, eq. 1); then the boundary nodes near corner points are pulled onto them.
//
// Beyond the paper, the construction checks what it needs and reports, instead of producing a
// broken mesh, the places where the tree must be refined:
// - the free edges form closed chains, one per loop, and a chain's projections must advance
//   along its loop exactly once around (projections that come back are clamped onto their
//   predecessor, giving the paper's P1 == P2 triangle; a chain that covers its loop zero or two
//   times means a feature thinner than the quadrants);
// - a projection segment must not enter an interior quadrant: take the next normal, then walk
//   along the curve (the paper's rule);
// - each corner is pulled onto the chain node whose projection is nearest along the curve.

#include <string>
#include <vector>

#include "core/free_facets.hpp"
#include "core/orthtree.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/quadrant_complex.hpp"

namespace febemesh::dim2 {

struct BoundaryQuadrantStats {
  std::size_t n_free_edges = 0;
  std::size_t n_chains = 0;
  std::size_t n_next_normal = 0;   ///< projections that took a further normal
  std::size_t n_walked = 0;        ///< projections found by walking along the curve
  std::size_t n_clamped = 0;       ///< projections clamped to keep the order along the curve
  std::size_t n_reachable_in_order = 0;  ///< clamped ones moved off a point reached only through an interior quadrant
  std::size_t n_triangles = 0;     ///< boundary quadrants with P1 == P2
  std::size_t n_corners_pulled = 0;
  std::size_t n_corners_inserted = 0;  ///< corners added between two boundary nodes
  std::size_t n_merged = 0;            ///< pairs of nearly coincident projections merged
  std::size_t n_corners_missed = 0;  ///< corners with no boundary node close enough
};

/// A place where the tree is too coarse for the construction, with the reason.
struct Problem {
  Point<2> where = Point<2>::Zero();
  std::string what;
};

/// Problem::what of a chain of free edges whose nodes project onto two loops: a part thinner
/// than the quadrants there (mesh2d's thin-parts retry looks for it).
inline constexpr char two_loops_problem[] = "a chain of free edges projects onto two loops";

struct QuadrantComplexResult {
  QuadrantComplex complex;
  BoundaryQuadrantStats stats;
  std::vector<Problem> problems;  ///< empty when the complex is complete
};

/// The free edges of the interior quadrants, passed from one step to the next: each step needs
/// free_facets(t, in), which costs a neighbour search per face of every interior quadrant.
using FreeEdges = std::vector<FreeFacet<2>>;

/// Drop interior quadrants so that no two of them meet only at a vertex (a pinch of the
/// interior region, which would make the boundary chains non-manifold). Returns how many.
/// `edges`, when given, holds free_facets(t, in) on entry and holds it for the new `in` on return.
/// `keys`, when given, is LeafKeys<2>(t) (else built here; apply_buffer needs the same).
std::size_t remove_pinches(const Orthtree<2>& t, Flags& in, FreeEdges* edges = nullptr, const LeafKeys<2>* keys = nullptr);

/// Drop interior quadrants nearer to the curve than `fraction` of their size (the buffer rule
/// against very thin boundary quadrants). Returns how many. `edges`, when given, receives
/// free_facets(t, in) for the new `in`. `keys` as for remove_pinches. The distances on
/// n_threads threads (curve queries only read it); the same result for every count.
std::size_t apply_buffer(const Orthtree<2>& t, Flags& in, const CurveBoundary& curve, double fraction,
                         FreeEdges* edges = nullptr, const LeafKeys<2>* keys = nullptr, int n_threads = 1);

struct BoundaryQuadrantOptions {
  int max_normals = 4;               ///< local minima tried before walking along the curve
  double corner_pull_radius = 0.5;   ///< pull a node onto a corner within this many cell sizes
  bool pull_corners = true;
  double merge_fraction = 0.25;      ///< merge projections closer than this x the cell size
  bool corners_may_fail = false;     ///< at the finest level, leave far corners unpulled
  int n_threads = 1;                 ///< for the nodes and the interior quadrants' rings
};

/// `edges`, when given, must be free_facets(t, in) (saves computing it again).
QuadrantComplexResult build_quadrant_complex(const Orthtree<2>& t, const Flags& in, const CurveBoundary& curve,
                                             const BoundaryQuadrantOptions& opt = {}, const FreeEdges* edges = nullptr);

}  // namespace febemesh::dim2
