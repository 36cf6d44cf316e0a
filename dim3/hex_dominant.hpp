#pragma once
// Step 6 in 3D, hex-dominant (`--elements hex`): the tetrahedral template mesh of the octant
// complex, after smoothing and optimisation, regrouped cell by cell into hexahedra where they
// conform and pyramids and tetrahedra elsewhere. The BE mesh follows: a boundary octant's
// surface face is a quad where it stays one, triangles otherwise.
//
// Why regroup the tet mesh rather than build hexes directly: the tet pipeline already untangles
// and smooths every node so that each cell's cones (cell centroid + face triangles) are valid,
// and its face rule is conforming. Merging only ever replaces valid cones by an element whose
// every corner Jacobian is checked, so the result cannot be worse than the tet mesh:
// - a "plain quad" face (4 distinct nodes, no hanging midpoint, no centre node) is covered by
//   exactly two cones of each cell beside it; both cells see the same two triangles;
// - a cell whose six faces are plain quads is a Hex8 (interior octant: its corners; boundary
//   octant: face corners Q1..Q4 + projections P1..P4) when all 8 corner Jacobians are positive
//   and its scaled Jacobian reaches `min_hex_scaled_jacobian`;
// - any other cell keeps its centroid: each plain quad face becomes a Pyramid5 with the centroid
//   as apex (the union of its two cones), every other face triangle stays a Tet4;
// - a quad face is split back into its two triangles, on both sides, when a pyramid on it has a
//   non-positive corner Jacobian, or a scaled Jacobian below both min_pyramid_scaled_jacobian
//   and its two cones', or when the pyramids on it (both sides) have a smallest dihedral angle
//   below both min_dihedral_deg and their cones' (a hex likewise against its cones; warped
//   quads), or when it is not seen as a quad by both cells; a hex with a split face
//   becomes pyramids. Repeated until nothing changes (splits only grow), so every
//   shared face is the same quad or the same two triangles on both sides;
// - a cell whose tetrahedra edge removal replaced (TetMesh::cells_changed: they are no longer
//   its cones) keeps them as they are and sees no quad, so every quad it shares is split.

#include <cstddef>

#include "core/orthtree.hpp"
#include "dim3/boundary_octants.hpp"
#include "dim3/templates3d.hpp"

namespace febemesh::dim3 {

struct HexDominantOptions {
  /// Cells whose hex would have a lower scaled Jacobian become pyramids and tets instead.
  double min_hex_scaled_jacobian = 0.2;
  /// A pyramid below this scaled Jacobian and below its two cones' stays two tets.
  double min_pyramid_scaled_jacobian = 0.2;
  /// A pyramid or hex whose smallest dihedral angle is below this and below the smallest of the
  /// tets it would replace stays tets (pyramids). 0 = no dihedral rule.
  double min_dihedral_deg = 15.0;
};

struct HexDominantStats {
  std::size_t n_hex = 0, n_pyramid = 0, n_tet = 0;
  std::size_t n_hex_candidates = 0;   ///< cells whose faces are all plain quads
  std::size_t n_hex_rejected = 0;     ///< candidates whose hex failed the Jacobian checks
  std::size_t n_hex_demoted = 0;      ///< hexes given up because a face had to be split
  std::size_t n_faces_split = 0;      ///< plain quad faces split back into two triangles
  std::size_t n_interface_quads = 0, n_interface_triangles = 0;
  double hex_volume = 0.0, total_volume = 0.0;
  /// Smallest dihedral angle (degrees) of the tetrahedra it started from: the merged mesh's is
  /// at least min(HexDominantOptions::min_dihedral_deg, this).
  double tets_min_dihedral_deg = 180.0;

  std::size_t n_elements() const { return n_hex + n_pyramid + n_tet; }
  /// Hexes over all solid elements.
  double hex_share() const { return n_elements() ? static_cast<double>(n_hex) / n_elements() : 0.0; }
  /// Volume in hexes over the solid's volume.
  double hex_volume_share() const { return total_volume > 0 ? hex_volume / total_volume : 0.0; }
};

/// Rewrites `fe` (the output of tetrahedralize, possibly smoothed: same connectivity, cell
/// per element) as the hex-dominant mesh of the same complex. Nodes no element uses any more
/// (centroids of hexes) are removed; the others keep their order. `t` and `complex` must be
/// the ones `fe` was built from.
HexDominantStats make_hex_dominant(const Orthtree<3>& t, const OctantComplex& complex, TetMesh& fe,
                                   const HexDominantOptions& opt = {});

}  // namespace febemesh::dim3
