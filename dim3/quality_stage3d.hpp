#pragma once
// The 3D pipeline's quality stage (internal to dim3: mesh3d_try), on a mesh whose tetrahedra are
// all positive: guarded Laplacian smoothing, the dihedral-angle sweeps (feature-line nodes
// sliding along their lines) and edge removal.

#include <functional>

#include "dim3/boundary_octants.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/templates3d.hpp"

namespace febemesh::dim3 {

/// The quality stage, on a mesh whose tetrahedra are all positive: guarded Laplacian
/// smoothing, the dihedral-angle sweeps and edge removal (what each step gained: the comments
/// at its options). Its counts go to r. A tetrahedral run frees the complex but its snap marks.
void improve_quality(const SurfaceBoundary& s, OctantComplex& complex, TetMesh& fe, const Options3d& opt,
                     const SurfacePointFn& surface_point, const std::function<P3(const BoundaryLocation&)>& surface_normal,
                     Result3d& r, const Progress3& say);

}  // namespace febemesh::dim3
