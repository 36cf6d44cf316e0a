#pragma once
// Geometric fidelity of a 3D mesh against the input surface (DESIGN.md "Validity and
// quality"): volume error, a two-sided Hausdorff estimate between the BE mesh and the surface,
// and how far the interface nodes are from the surface.

#include "core/mesh.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::dim3 {

struct Fidelity3d {
  double surface_volume = 0.0;      ///< enclosed by the input surface
  double fe_volume = 0.0;           ///< sum of the FE element volumes
  double volume_rel_error = 0.0;    ///< |fe - surface| / surface
  double be_to_surface = 0.0;       ///< max over BE triangle samples of the distance to the surface
  double surface_to_be = 0.0;       ///< max over surface vertices and triangle centroids to the BE mesh
  double hausdorff = 0.0;           ///< max of the two
  double hausdorff_rel = 0.0;       ///< hausdorff / diagonal of the surface's bounding box
  double max_node_distance = 0.0;   ///< max distance of an interface node to the surface
};

/// How far the input surface gets from the BE mesh of `m` (its triangles): the largest distance
/// of a surface vertex or triangle centroid to them (Fidelity3d::surface_to_be); 0 without any.
double surface_to_be_distance(const Mesh<3>& m, const SurfaceBoundary& s);

/// `samples` >= 1 sets the barycentric sampling density per BE triangle (samples per edge).
Fidelity3d measure_fidelity(const Mesh<3>& m, const SurfaceBoundary& s, int samples = 4);

}  // namespace febemesh::dim3
