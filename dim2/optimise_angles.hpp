#pragma once
// Beyond the paper: a local search on node positions that raises the worst corner angle of a
// 2D mesh of triangles and quadrilaterals, measured against each kind's bar:
//   triangle  q = smallest angle / 20 deg
//   quad      q = min over corners of min(angle, 180 - angle) / 30 deg   (the [30, 150] bar)
// so q >= 1 means the element meets its bar. Laplacian smoothing and the triangle quality pass
// (improve2d) move a node toward the centroid of its neighbours; that is not enough for quads,
// whose largest angle matters as much as the smallest, nor for the quads made by splitting
// triangles (whose corner angles start as the triangle's), and it stops short of 30 deg for
// triangles next to the curve. Here each node whose elements are below `target` tries the centroid of its neighbours and small pattern steps around its
// position, and keeps the best candidate only if the worst q of its elements rises. No element
// ever inverts (an inverted or reflex corner gives q < 0, which is never accepted).
// Deterministic: nodes are visited in index order, candidates in a fixed order.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/mesh.hpp"
#include "dim2/improve2d.hpp"

namespace febemesh::dim2 {

/// Worst corner angle of element e measured against its kind's bar (see above); < 0 when a
/// corner is reflex or the element is inverted.
double angle_quality(const Mesh<2>& m, std::size_t e);

struct AngleOptimiseOptions {
  int rounds = 8;         ///< sweeps over the nodes
  double target = 1.25;   ///< nodes whose elements all reach this q are left alone
  /// When > 0, triangles aim at this q instead (mixed meshes: 1.5, i.e. 30 deg, while quads
  /// keep target); the search then raises the worst q relative to each element's aim.
  double triangle_target = 0.0;
  /// Distance from a point to the curve. When set, a sliding interface node may move only where
  /// its two BE chords stay as close to the curve as they were (the larger of the two chord
  /// midpoints' distances does not grow), so raising angles never costs boundary fidelity.
  std::function<double(const Point<2>&)> curve_distance;
  /// Threads for the per-element set-up, the mesh's worst q and the sweeps (in slabs,
  /// core/partitioned_sweep.hpp; `slide` and curve_distance must then be safe to call
  /// concurrently for different nodes); the same mesh for every count.
  int n_threads = 1;
  /// Fill AngleOptimiseStats::worst_before and worst_after: two passes over the elements
  /// (most of them by their largest corner cotangent); the mesh is the same without. (The 2D
  /// pipeline does not report them.)
  bool measure_worst = true;
};

struct AngleOptimiseStats {
  std::size_t moves = 0;
  double worst_before = 0.0;  ///< smallest q over the mesh (triangles scaled by target / triangle_target when set)
  double worst_after = 0.0;   ///< (both 0 without AngleOptimiseOptions::measure_worst)
};

/// `locked` as in improve_mesh: 0 free, 1 fixed, 2 interface node that slides through `slide`.
AngleOptimiseStats optimise_angles(Mesh<2>& m, const std::vector<std::uint8_t>& locked,
                                   const AngleOptimiseOptions& opt = {}, const SlideFn& slide = {});

}  // namespace febemesh::dim2
