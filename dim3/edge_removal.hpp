#pragma once
// Edge removal (Shewchuk, "Two discrete optimization algorithms for the topological
// improvement of tetrahedral meshes", 2002): the n tetrahedra around an edge ab are replaced by
// the 2(m - 2) tetrahedra joining a and b to a triangulation of the m-gon of their other nodes
// (the edge's link), chosen by Klincsek's dynamic programme to maximise the worst of them. At a
// surface edge the link is open (m = n + 1) and closing it swaps the edge of the surface mesh:
// the two interface triangles at ab become two at the link's ends. At a concave surface edge
// (more than pi inside) the new tetrahedra also fill the tetrahedron of ab and the link's ends,
// outside the old surface: the same as adding it and removing the edge, now inside.
//
// Node moves cannot open a wedge that the mesh's connectivity fixes: the dihedral angles of the
// tetrahedra around an edge add up to the angle at the edge (2 pi inside, the surface mesh's
// angle at a surface edge), so four tetrahedra around a surface edge whose interface triangles
// meet at 62 deg stay under 15.5 deg whatever their free nodes do (anchor L5, a surface edge
// across a concave feature line the surface mesh misses: its five tetrahedra under 10 deg).
//
// Edge contraction, where no removal helps a tetrahedron under opt.contract_below_deg: node u
// of a short edge uv goes, its tetrahedra at v go with it, and its other tetrahedra and interface
// triangles take v instead. Neither removal nor node moves can lengthen an edge that the surface
// mesh pins short: fandisk L5's seven tetrahedra under 15 deg all hold a surface edge of 0.0012
// (a smooth-surface node beside a feature-line node) among edges of 0.015-0.03. Taken only when
// the link condition holds (Dey et al.: the links of u and v meet in the link of uv, the
// interface closed by a cone from outside), so the mesh stays a manifold of the same topology.

#include <cstdint>
#include <functional>
#include <vector>

#include "core/boundary.hpp"
#include "core/mesh.hpp"
#include "dim3/node_tets.hpp"

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
  /// Tetrahedra below this (degrees) that no other removal mends also try swapping their
  /// concave surface edges (with surface_normal). 0: never. The new tetrahedra then fill the
  /// tetrahedron between the old and the new interface triangles too, outside the old surface,
  /// so only where no interface triangle reaches into it. Without them spool L4 kept two
  /// tetrahedra at 14.33 deg: an interior node 0.003 from a surface edge of 0.046 along a
  /// concave crease, whose two interface triangles (angles of 161 and 170 deg) met at 283 deg
  /// inside; no node could move out of it (a search of the interior node's positions found
  /// nothing better than 14.34), the swap makes the two tetrahedra 22.2 and 29.9 deg.
  double concave_below_deg = 15.0;
  /// Tetrahedra below this (degrees) whose edges no removal mends try contracting an edge,
  /// shortest first. 0: never. A contraction is taken if it raises the worst angle of the
  /// tetrahedra at the node it removes (contract_min_gain_deg). Only nodes inside or on smooth
  /// surface (where.kind Smooth) go, a surface node only into another surface node along an
  /// interface edge, and then only if the new interface triangles fit the surface (as for a
  /// surface swap: needs surface_normal). The mesh's nodes are renumbered (EdgeRemovalStats::node_map).
  double contract_below_deg = 0.0;
  /// A contraction is taken if it raises the worst angle of the tetrahedra at the removed node
  /// by more than this (degrees). Not min_gain_deg: a contraction removes a node, so it cannot
  /// come back, and the node moves after it lengthen the edges around the place. fandisk L6's
  /// worst tetrahedron (14.84 deg) held a smooth surface edge of 0.0015 among edges of
  /// 0.0085-0.018, whose contraction raised its node's worst angle by 0.09 deg: at 0.5 deg it
  /// stayed; at 0 the sweeps after it took the mesh to 15.94 deg.
  double contract_min_gain_deg = 0.0;
  /// Per node: 1 = never contracted away (the pipeline: the feature corners). Empty: none.
  std::vector<std::uint8_t> keep;
  /// Per node: when not empty, only the tetrahedra with a node marked 1 are tried (and the
  /// tetrahedra the removals make). Empty: every tetrahedron under below_deg.
  std::vector<std::uint8_t> only_at;
  /// Threads for the scan of every tetrahedron's quality (the removals themselves run in order
  /// on one); the result is the same for every count.
  int n_threads = 1;
  /// tet_search_rank of every tetrahedron, handed between passes (TetOptimizeOptions::ranks).
  /// In: when it holds one value a tetrahedron, those of the input at its points, which the scan
  /// uses instead of ranking them all; otherwise they are ranked. Out: those of the output
  /// tetrahedra (the survivors' as handed in or ranked, the new ones ranked). Null: neither.
  std::vector<double>* ranks = nullptr;
  /// In (when not null): the tetrahedra at each node of the input mesh, used instead of
  /// listing them again where they fit its size (the caller vouches for the rest: the tet
  /// optimiser's TetOptimizeOptions::incidence); taken, so left empty.
  NodeTets* incidence = nullptr;
};

struct EdgeRemovalStats {
  std::size_t removed = 0;          ///< edges removed
  std::size_t surface_swapped = 0;  ///< of them, surface edges
  std::size_t concave_swapped = 0;  ///< of those, concave ones (EdgeRemovalOptions::concave_below_deg)
  /// With `cell`: the cells (ascending, each once) that lost a tetrahedron, so whose
  /// tetrahedra are no longer their template's (make_hex_dominant leaves them as they are).
  std::vector<std::int32_t> cells_changed;
  std::size_t contracted = 0;  ///< edges contracted (nodes removed)
  /// With contractions: old node id -> new one (-1: removed); the mesh's points are compacted
  /// in order. Empty when no node was removed. Per-node arrays of the caller follow it
  /// (remap_nodes).
  std::vector<std::int32_t> node_map;
};

/// Removes edges of bad tetrahedra from `mesh` (all Tet4; interface all Tri3, outward) while a
/// removal raises the worst angle around its edge, and contracts edges of those still under
/// opt.contract_below_deg. `where` (per node, patch >= 0 on the surface) is read only; after a
/// contraction it, like every per-node array, needs remap_nodes(stats.node_map, ...).
/// Per-element arrays stay in step: mesh.level, mesh.from_boundary_cell and, if not null,
/// `cell` (new tetrahedra take the values of the first tetrahedron they replace). Element order
/// changes: survivors keep their order, new ones come last.
EdgeRemovalStats remove_bad_edges(Mesh<3>& mesh, const std::vector<BoundaryLocation>& where, std::vector<std::int32_t>* cell,
                                  const EdgeRemovalOptions& opt);

/// values[node_map[v]] = values[v] for the kept nodes, in order; the removed ones' entries go.
/// Nothing when node_map is empty or values is (an unused per-node array).
template <class T> void remap_nodes(const std::vector<std::int32_t>& node_map, std::vector<T>& values) {
  if (node_map.empty() || values.empty()) return;
  std::size_t k = 0;
  for (std::size_t v = 0; v < node_map.size() && v < values.size(); ++v)
    if (node_map[v] >= 0) values[k++] = values[v];
  values.resize(k);
}

}  // namespace febemesh::dim3
