#pragma once
// Step 6 in 3D: tetrahedra from templates over the interior octants (with hanging nodes) and
// the boundary octants, and step 5: the BE mesh (the boundary octants' surface faces), sharing
// nodes.
//
// Every cell is split as "cell centroid + each face triangulated" (a cone per face triangle).
// Conformity rests on one face rule that both cells sharing a face evaluate identically from
// global data only (lattice nodes and node ids):
// - a lattice square whose centre is a lattice node (finer octants on the other side) is its
//   four sub-squares, each by the rule;
// - a square with lattice nodes at some edge midpoints is fanned from its centre, a node added
//   once per lattice point and shared by both sides;
// - a plain quad (square, or a boundary octant's side Qi Qj Pj Pi) is split by the diagonal
//   through its smallest node id;
// - coincident projections (the same node twice) shrink a face to a triangle or nothing; cones
//   with a repeated node are dropped, which leaves prisms, pyramids and tets.
// The boundary octant's surface face belongs to one cell only: its diagonal is chosen for the
// better triangles; with hanging midpoints it is fanned from a surface point.

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "core/mesh.hpp"
#include "core/orthtree.hpp"
#include "dim3/boundary_octants.hpp"

namespace febemesh::dim3 {

/// Surface point near p with its location (the fan centre of a surface face with hanging nodes).
using SurfacePointFn = std::function<std::pair<P3, BoundaryLocation>(const P3&)>;

struct TetMesh {
  Mesh<3> mesh;
  /// Per mesh node: where it lies on the surface (patch >= 0 for interface nodes).
  std::vector<BoundaryLocation> where;
  /// Per solid element: the cell it came from (index into complex.interior, then
  /// complex.boundary offset by complex.interior.size()).
  std::vector<std::int32_t> cell;
  /// Cells (ascending, each once) whose tetrahedra are no longer the template's cones: edge
  /// removal (dim3/edge_removal.hpp) replaced some of them. make_hex_dominant keeps them tets.
  std::vector<std::int32_t> cells_changed;
  /// Per node as tetrahedralize made them (the complex's nodes first): its id now, -1 where an
  /// edge contraction removed it (dim3/edge_removal.hpp). Empty: the ids are unchanged.
  std::vector<std::int32_t> node_map;
  std::size_t n_dropped_degenerate = 0;  ///< cones with a repeated node (degenerate octants)
  std::size_t n_fins_cancelled = 0;      ///< pairs of back-to-back triangles of one cell, dropped
};

/// tetrahedralize's interior part: the interior octants' tetrahedra and the nodes they add
/// (fan centres and centroids, after the complex's nodes). It depends on the tree, the interior
/// octants and the lattice, not on where the complex's nodes are, so a call on the same tree
/// and complex with moved nodes (the repair's untangling rounds) takes the tetrahedra from the
/// last call's mesh, which begins with them. Held here: where the nodes it adds come from, its
/// fan centres, and a hash of the tetrahedra, so that a last mesh whose first tetrahedra are not
/// these is not used. 16 B a node at most (copies of the tetrahedra, then of the nodes and the
/// fan map, raised sphere966 L6's peak memory by up to 6.6 MB).
struct InteriorTets {
  bool filled = false;
  std::size_t n_complex_points = 0, n_interior = 0, n_tets = 0;  ///< what it was made for (checked)
  /// Per node it adds, in order: a fan centre's lattice point key, or centroid_tag | the
  /// interior octant's index (the positions are computed again, the same numbers).
  std::vector<std::uint64_t> origin;
  static constexpr std::uint64_t centroid_tag = std::uint64_t(1) << 63;
  std::vector<std::pair<std::uint64_t, std::int32_t>> fan;  ///< fan centre nodes by key, ascending
  std::size_t n_dropped_degenerate = 0;
  std::uint64_t hash = 0;  ///< of the tetrahedra's nodes, levels and cells
};

/// Node ids 0..complex.points.size()-1 of the result are the complex's nodes.
/// The interior octants' tetrahedra are built on n_threads threads; the result is the same for
/// every count. With `kept` and `last` (the result of the call that filled `kept`, or of a
/// later one, its nodes moved): the interior part taken from them when `kept` is filled for
/// this complex (the same numbers of nodes and interior octants; the caller vouches for the
/// tree) and `last` begins with its tetrahedra; else built, and `kept` filled. The same result
/// either way.
TetMesh tetrahedralize(const Orthtree<3>& t, const OctantComplex& complex, const SurfacePointFn& surface_point,
                       int n_threads = 1, InteriorTets* kept = nullptr, const TetMesh* last = nullptr);

/// The triangles (outward, CCW seen from outside the cell) of a lattice square face with
/// corners `q` counter-clockwise seen from outside, by the face rule above. `lattice_node`
/// answers a lattice point's node id (-1 if none); `fan_node` gives (or creates) the fan
/// centre node at a lattice point.
void triangulate_square(const std::array<LatticePoint<3>, 4>& q, std::uint32_t len,
                        const std::function<std::int32_t(const LatticePoint<3>&)>& lattice_node,
                        const std::function<std::int32_t(const LatticePoint<3>&)>& fan_node,
                        std::vector<std::array<std::int32_t, 3>>& out);

/// A polygon of node ids split by the diagonal through its smallest id (4 nodes), or kept
/// (3 nodes), after removing cyclically repeated ids; appended to `out`.
void triangulate_quad_by_id(std::array<std::int32_t, 4> q, std::vector<std::array<std::int32_t, 3>>& out);

}  // namespace febemesh::dim3
