#pragma once
// The 3D pipeline's untangling (internal to dim3: pipeline3d, mesh3d_try): which tetrahedra the
// templates left inverted and which interface triangles fold, the moves of surface nodes that
// unfold them, and the tet_optimize passes that untangle the rest, kept within their cells'
// reach when asked.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/box.hpp"
#include "core/mesh.hpp"
#include "core/orthtree.hpp"
#include "dim3/boundary_octants.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/templates3d.hpp"
#include "dim3/tet_optimize.hpp"

namespace febemesh::dim3 {

/// Solid elements that are inverted or flat (signed volume below 1e-12 of their edge cubed),
/// ascending; marked on n_threads threads. The longest edge as the root of the largest squared
/// length: the same number as the largest root (sqrt is correctly rounded, so monotone), one
/// root instead of six (with the points read in place, this check was 4% of sphere966 L6's run
/// on one thread, twice a run).
std::vector<std::size_t> inverted_elements(const Mesh<3>& m, int n_threads = 1);

/// A node untangle moved: where it was in the mesh and in the complex before.
struct UntangleUndo {
  std::int32_t node = -1;
  P3 mesh_point, complex_point;
  BoundaryLocation complex_where;
};

/// Surface nodes of inverted tets move to another surface point when that leaves fewer of their
/// tets inverted: the projection of the mean of their surface neighbours (a smoothed
/// projection, which unfolds crossed projections), halfway there, or the first surface point
/// along the mean outward normal of their free faces. Every candidate must stay admissible from
/// all the face nodes projecting onto it. `bad`: the mesh's inverted elements
/// (inverted_elements). Returns how many nodes moved. With `undo`, each moved node's state
/// before the move is appended to it (UntangleUndo).
std::size_t untangle(const Orthtree<3>& t, const Flags& in, const SurfaceBoundary& s, double graze, bool graze_region,
                     double graze_length, const std::vector<std::size_t>& bad, OctantComplex& oc, TetMesh& fe,
                     std::vector<UntangleUndo>* undo = nullptr);

/// True when untangle's moves left the complex as it was, bit for bit: every moved node went to
/// the complex point (and surface location) it already had, the mesh's untangled position only
/// having changed. The next round's tetrahedra are then this round's again.
bool complex_unchanged(const std::vector<UntangleUndo>& undo, const OctantComplex& oc);

/// Interface triangles folded over on the surface: their normal points against the surface's
/// (the sum of the normals of the surface triangles their nodes lie on). Positive tetrahedra do
/// not exclude this: a surface node can slide over its neighbours, and the mesh then covers a
/// strip twice (the validator sees its nodes on other elements' facets). Marked on n_threads
/// threads (the same list).
std::vector<std::size_t> folded_faces(const Mesh<3>& m, const std::vector<BoundaryLocation>& where,
                                      const SurfaceBoundary& s, int n_threads);

/// Nodes the optimisation must not move: feature corners, and with `features` the nodes
/// snapped onto feature lines too.
std::vector<std::uint8_t> fixed_nodes(const OctantComplex& oc, const TetMesh& fe, bool features);

/// One untangling pass (tet_optimize with untangle_only): the max-min node moves, or with
/// `escobar` the smooth last resort. Surface nodes stay on the surface, corners stay put.
TetOptimizeStats untangle_pass(TetMesh& fe, const OctantComplex& oc, int sweeps, bool escobar,
                               const SurfaceProjection& project,
                               const std::function<P3(const BoundaryLocation&)>& normal, int n_threads,
                               const std::vector<Box<3>>& bounds = {});

/// One line for the progress report: `pass`, then its inverted tetrahedra and folded interface
/// triangles before and after.
std::string untangle_summary(const std::string& pass, const TetOptimizeStats& ts);

/// Per node of fe: the box the untangling's moves keep it in (Options3d::untangle_reach), for
/// the nodes off the surface: the bounding box of its cells' nodes as built, each grown by
/// `reach` x the cell's size. Surface nodes get an empty box (unbounded).
std::vector<Box<3>> move_bounds(const Orthtree<3>& t, const OctantComplex& oc, const TetMesh& fe, double reach);

}  // namespace febemesh::dim3
