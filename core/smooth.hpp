#pragma once
// Guarded Laplacian smoothing (paper, step 4; DESIGN.md pipeline step 4), generic over Dim.
// Gauss-Seidel sweeps in node order (or slab order, `parts`): an interior node moves to the
// centroid of its neighbours along element edges. A move is accepted only if no incident element inverts and the minimum
// scaled Jacobian of the incident elements does not drop. Boundary nodes (nodes of boundary
// facets of the solid) stay put unless `project` is given: then they move to the centroid of
// their neighbours along the boundary and are projected back, under the same guard.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh {

template <int Dim> struct SmoothOptions {
  /// The paper uses 4. In 3D fewer, or only the nodes near the surface, cost the tet optimiser's
  /// minimum (issue 8, CLI, min dihedral deg): 2 iterations: anchor L4 12.73 -> 7.99; only nodes
  /// within 2 (4) tet-edge rings of the surface: sphere966 L4 28.17 -> 28.06 (28.12), L5
  /// 27.67 -> 27.30 (27.58).
  int n_iterations = 4;
  /// Per node, 1 = never moves (e.g. corners). Empty = none fixed explicitly.
  std::vector<std::uint8_t> fixed;
  /// The caller knows that `fixed` holds every node of the solid's boundary (the 3D pipeline:
  /// all its surface nodes): the boundary is then not looked for (a facet sort, 3.5% of a
  /// sphere966 level-4 mesh3d run). Without project only. A boundary node left out of `fixed`
  /// would then move like an interior node (the guard still keeps every element positive).
  bool boundary_fixed = false;
  /// Maps a point near the boundary onto it; when set, boundary nodes may slide.
  std::function<Point<Dim>(const Point<Dim>&)> project;
  /// A node whose target lies within this share of its longest edge (max norm) of where it
  /// stands stays there, as if the target were its position: on a grid the centroid of the
  /// neighbours is the node itself up to rounding, and such moves (97% of the tries in the 2D
  /// flange at 5.4 M triangles, under 1e-12 of the edge) change no quality beyond rounding but
  /// each costs the guard and wakes the neighbours. 0 = every target that differs moves.
  double min_move = 0.0;
  /// Threads for the neighbour lists, the element states and the sweeps (project must then be
  /// safe to call concurrently); the result is the same, bit for bit, for every count.
  int n_threads = 1;
  /// When > 0, the sweeps visit the nodes in a partitioned order instead of node order
  /// (core/partitioned_sweep.hpp: that many slabs, each slab's inner nodes, then the nodes on
  /// the cuts), the same mesh for every thread count.
  int parts = 0;
  /// Fill SmoothStats::min_quality_before and _after, which needs every element's state up
  /// front. Without (the 2D pipeline), an element's state is evaluated when a visit first reads
  /// it, the same numbers: most 2D nodes settle without reading any (NimbusSans U0067 at 10^6
  /// triangles, one thread: the stage 0.084-0.087 s -> 0.071-0.075 in alternating runs).
  bool min_quality = true;
  /// When set, and the sweeps gather each node's neighbours from its triangles and quads (every
  /// boundary node fixed, no project, parts > 0), filled on return with a byte per node: 1
  /// where the node's last visit found the centroid of its neighbours (ascending, summed in that
  /// order) within min_move of where it stands, or found no neighbour, and no node of its
  /// elements has moved since; so the same test at the returned points says the same. Else
  /// left empty. (The 2D quality pass starts from it instead of gathering every node again.)
  std::vector<std::uint8_t>* at_rest = nullptr;
};

struct SmoothStats {
  int iterations = 0;
  std::size_t moves_accepted = 0;
  std::size_t moves_rejected = 0;
  double min_quality_before = 0.0;  ///< min scaled Jacobian of the solid elements (min_quality)
  double min_quality_after = 0.0;   ///< (0 without SmoothOptions::min_quality)
};

/// Whether `target` lies within `share` of node v's longest edge to `nbrs` (max norm) of where v
/// stands: a move of rounding size (SmoothOptions::min_move; the 2D quality pass too).
template <int Dim>
bool within_rounding(const std::vector<Point<Dim>>& points, std::int32_t v, std::span<const std::int32_t> nbrs,
                     const Point<Dim>& target, double share) {
  const Point<Dim>& p = points[static_cast<std::size_t>(v)];
  double edge = 0;
  for (const std::int32_t w : nbrs) edge = std::max(edge, (points[static_cast<std::size_t>(w)] - p).cwiseAbs().maxCoeff());
  return (target - p).cwiseAbs().maxCoeff() <= share * edge;
}

/// Moves mesh.points in place; the connectivity is unchanged.
template <int Dim> SmoothStats smooth(Mesh<Dim>& mesh, const SmoothOptions<Dim>& options = {});

}  // namespace febemesh
