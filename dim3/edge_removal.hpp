#pragma once
// Edge removal (Shewchuk, "Two discrete optimization algorithms for the topological
// improvement of tetrahedral meshes", 2002): the n tetrahedra around an edge ab are replaced by
// the 2(m - 2) tetrahedra joining a and b to a triangulation of the m-gon of their other nodes
// (the edge's link), chosen by Klincsek's dynamic programme to maximise the worst of them. At a
// surface edge the link is open (m = n + 1) and closing it swaps the edge of the surface mesh:
// the two interface triangles at ab become two at the link's ends.
//
// Node moves cannot open a wedge that the mesh's connectivity fixes: the dihedral angles of the
// tetrahedra around an edge add up to the angle at the edge (2 pi inside, the surface mesh's
// angle at a surface edge), so four tetrahedra around a surface edge whose interface triangles
// meet at 62 deg stay under 15.5 deg whatever their free nodes do (anchor L5, a surface edge
// across a concave feature line the surface mesh misses: its five tetrahedra under 10 deg).

#include <cstdint>
#include <functional>
#include <vector>

#include "core/boundary.hpp"
#include "core/mesh.hpp"

namespace febemesh::dim3 {

struct EdgeRemovalOptions {
  /// Edges of tetrahedra whose smallest dihedral angle is below this (degrees) are tried.
  double below_deg = 30.0;
  /// Links of more nodes are not tried (the programme is cubic in them).
  int max_link = 8;
  /// A removal is taken if it raises the worst dihedral angle of the tetrahedra it replaces by
  /// at least this (degrees).
  double min_gain_deg = 0.5;
  /// Outward unit normal of the surface at a location. Without it surface edges stay. With it a
  /// surface edge is swapped only if the new interface triangles fit the surface at least as
  /// well as the old ones (the smallest cosine between a triangle's normal and the surface
  /// normals at its nodes does not drop, and stays positive), and never an edge between two
  /// feature-line or corner nodes (it may be the feature line itself).
  std::function<Point<3>(const BoundaryLocation&)> surface_normal;
  /// Threads for the scan of every tetrahedron's quality (the removals themselves run in order
  /// on one); the result is the same for every count.
  int n_threads = 1;
};

struct EdgeRemovalStats {
  std::size_t removed = 0;          ///< edges removed
  std::size_t surface_swapped = 0;  ///< of them, surface edges
  /// With `cell`: the cells (ascending, each once) that lost a tetrahedron, so whose
  /// tetrahedra are no longer their template's (make_hex_dominant leaves them as they are).
  std::vector<std::int32_t> cells_changed;
};

/// Removes edges of bad tetrahedra from `mesh` (all Tet4; interface all Tri3, outward) while a
/// removal raises the worst angle around its edge. `where` (per node, patch >= 0 on the surface)
/// is read only. Per-element arrays stay in step: mesh.level, mesh.from_boundary_cell and, if
/// not null, `cell` (new tetrahedra take the values of the first tetrahedron they replace).
/// Element order changes: survivors keep their order, new ones come last.
EdgeRemovalStats remove_bad_edges(Mesh<3>& mesh, const std::vector<BoundaryLocation>& where, std::vector<std::int32_t>* cell,
                                  const EdgeRemovalOptions& opt);

}  // namespace febemesh::dim3
