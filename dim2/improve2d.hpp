#pragma once
// Beyond the paper ("further smoothing processes can be used, if necessary"): a quality pass on
// the finished 2D FE mesh. Alternates
//   - edge flips between two triangles (interface edges never flip) when the flip raises the
//     smaller of the two triangles' smallest angles, and
//   - guarded smoothing: a free node moves toward the centroid of its neighbours (full step,
//     then half, then a quarter) only if the smallest angle of its elements rises.
// The mesh stays conforming and valid: every accepted change keeps all elements positive.
// Interface nodes and the interface elements are untouched. Deterministic (fixed orders).

#include <cstdint>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh::dim2 {

struct ImproveStats {
  std::size_t flips = 0;
  std::size_t moves = 0;
  double min_angle_before = 0.0;  ///< degrees, over all solid elements
  double min_angle_after = 0.0;
};

/// Smallest corner angle (degrees) of a triangle or quadrilateral; <= 0 when inverted.
double min_corner_angle_deg(const Mesh<2>& m, std::size_t e);

/// `locked[v]` != 0: node v never moves (interface nodes).
ImproveStats improve_mesh(Mesh<2>& m, const std::vector<std::uint8_t>& locked, int rounds = 4);

}  // namespace febemesh::dim2
