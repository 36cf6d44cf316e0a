#pragma once
// Where a tetrahedral mesh's BE mesh misses the surface it was built for: points of the surface
// farther from the interface triangles than a local allowance. A handle cut where the solid is
// thinner than the octants (a wrong Euler characteristic) leaves its stretch of surface without
// interface triangles near it; the mesh3d repair can then refine the octants there instead of
// every octant on the surface (Options3d::topology_gap).

#include <functional>
#include <vector>

#include "core/mesh.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::dim3 {

struct MissedPoint {
  Point<3> p;
  double distance = 0.0;  ///< to the nearest interface triangle
};

/// Samples of each surface triangle (its corners, and a barycentric grid no coarser than
/// `spacing` along its longest edge, at most 256 steps), those farther from m's interface
/// triangles than allowance(p), in triangle order. Empty when m has no interface triangle.
std::vector<MissedPoint> missed_surface(const Mesh<3>& m, const SurfaceBoundary& s, double spacing,
                                        const std::function<double(const Point<3>&)>& allowance);

}  // namespace febemesh::dim3
