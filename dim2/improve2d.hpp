#pragma once
// Beyond the paper ("further smoothing processes can be used, if necessary"): a quality pass on
// the finished 2D FE mesh. Alternates
//   - edge flips between two triangles (interface edges never flip) when the flip raises the
//     smaller of the two triangles' smallest angles, and
//   - guarded smoothing: a free node moves toward the centroid of its neighbours (full step,
//     then half, then a quarter) only if the smallest angle of its elements rises.
// The mesh stays conforming and valid: every accepted change keeps all elements positive.
// Interface elements keep their nodes; interface nodes only slide along the curve (optional).
// Deterministic (fixed orders: flips by edge key, nodes in the slab order of
// core/partitioned_sweep.hpp).

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh::dim2 {

/// The quality pass's rounding share: a target within 1e-10 of v's longest edge from v is where v
/// stands up to rounding (within_rounding). On a grid the centroid is the node itself but for a
/// few ulps (1e-13 of an edge at level 10, 3e-11 at level 17); trying it cost the guard three
/// steps at most of the nodes (flange, 5.4 M triangles). Such a node stays (it could at best
/// gain ~1e-8 deg). The same test in improve_mesh and improve_mesh_ref.
inline constexpr double quality_rounding_share = 1e-10;

struct ImproveStats {
  std::size_t flips = 0;
  std::size_t moves = 0;
  double min_angle_before = 0.0;  ///< degrees, over all solid elements (measure_min)
  double min_angle_after = 0.0;   ///< (both 0 without ImproveOptions::measure_min)
};

/// Smallest corner angle (degrees) of a triangle or quadrilateral; <= 0 when inverted.
double min_corner_angle_deg(const Mesh<2>& m, std::size_t e);
/// Slow twin of min_corner_angle_deg (atan2 at every corner): the same value, bit for bit.
double min_corner_angle_deg_ref(const Mesh<2>& m, std::size_t e);

/// Maps a point near the curve onto it for interface node v, or returns the node's current
/// position when it must not move there (e.g. onto another loop).
using SlideFn = std::function<Point<2>(std::int32_t v, const Point<2>& target)>;

/// Each node's neighbours along the BE mesh (the other ends of its interface elements),
/// ascending, without repeats; empty for nodes off the interface. CSR: 4 bytes a node where a
/// vector per node was 24 (at the memory peak of optimise_angles).
struct InterfaceNeighbours {
  std::vector<std::int32_t> first;  ///< node v's neighbours are nbr[first[v], first[v + 1])
  std::vector<std::int32_t> nbr;
  std::span<const std::int32_t> of(std::size_t v) const {
    return {nbr.data() + first[v], static_cast<std::size_t>(first[v + 1] - first[v])};
  }
};
InterfaceNeighbours interface_neighbours(const Mesh<2>& m);

struct ImproveOptions {
  int rounds = 4;  ///< flip passes then a smoothing sweep, this many times
  /// Moves interface nodes (locked 2) along the curve; without, they stay as locked 1.
  SlideFn slide;
  /// The per-element set-up, the mesh's smallest angle and the smoothing sweeps (in slabs,
  /// core/partitioned_sweep.hpp; `slide` must then be safe to call concurrently for different
  /// nodes) run on n_threads threads, the flips on one; the same mesh for every count.
  int n_threads = 1;
  /// Optional, a byte per node: SmoothOptions::at_rest of a smoothing with min_move at most
  /// quality_rounding_share that ended at m's points and elements; its free nodes at rest start
  /// settled, as their first visit would leave them. Taken over (left empty). The same mesh with
  /// it or without.
  std::vector<std::uint8_t>* at_rest = nullptr;
  /// Fill ImproveStats::min_angle_before and _after (two passes over the elements); the mesh is
  /// the same without. (The 2D pipeline does not report them.)
  bool measure_min = true;
};

/// `locked[v]`: 0 free, 1 never moves (corners), 2 interface node that may slide along the curve
/// through opt.slide (toward the midpoint of its two interface neighbours).
ImproveStats improve_mesh(Mesh<2>& m, const std::vector<std::uint8_t>& locked, const ImproveOptions& opt = {});
/// Slow twin of improve_mesh (recomputes every angle, sorts all half-edges each pass): the same
/// mesh, for tests.
ImproveStats improve_mesh_ref(Mesh<2>& m, const std::vector<std::uint8_t>& locked, int rounds = 4,
                              const SlideFn& slide = {});

}  // namespace febemesh::dim2
