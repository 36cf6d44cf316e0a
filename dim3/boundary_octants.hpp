#pragma once
// The octree extension of the paper's "Generation of boundary quadrants" (its conclusion): one
// boundary octant between each free face of the interior octants and the surface, made of the
// face and the projections of its nodes (corners and hanging edge midpoints), i.e. a hexahedron
// Q1..Q4 P1..P4 whose sides are split at hanging midpoints.
//
// As in 2D the construction checks what it needs and reports the places where the tree is too
// coarse instead of producing a broken mesh:
// - the interior region must be a manifold: octants meeting only at an edge or a vertex are
//   dropped (remove_pinches), and octants too close to the surface too (apply_buffer, against
//   flat boundary octants);
// - a projection segment must not enter an interior octant nor cross the surface: take the next
//   local minimum of the distance, else report a Problem;
// - projections landing on the same surface point share one node (degenerate octants become
//   prisms, pyramids or tets in the templates);
// - feature corners pull the nearest boundary node, then nodes near a feature line are
//   projected onto it (the 3D version of pulling to corners).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/free_facets.hpp"
#include "core/orthtree.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::dim3 {

/// A boundary octant: a free face of the interior octants and the projections of its nodes.
struct BoundaryOctant {
  std::size_t leaf = no_leaf;  ///< the interior octant behind the face
  Cell<3> cell;                ///< the leaf, or its descendant for a sub-face (see FreeFacet)
  int face = -1;               ///< face of `cell`
  /// Face nodes counter-clockwise seen from outside the interior octant (FaceCorners<3> order),
  /// hanging edge midpoints included; lattice node ids.
  std::vector<std::int32_t> ring;
  std::array<std::uint8_t, 4> corner_slot{};  ///< position in `ring` of each face corner
};

/// Interior octants plus boundary octants with shared nodes: what the templates work on.
/// Nodes 0..n_lattice-1 are the lattice nodes of the interior octants (same ids as `lattice`),
/// the others are surface nodes (projections).
struct OctantComplex {
  LatticeNodes<3> lattice;
  std::vector<P3> points;
  std::vector<BoundaryLocation> where;     ///< patch >= 0 for surface nodes
  std::vector<std::int32_t> projection;    ///< per lattice node: its surface node, or -1
  std::vector<std::size_t> interior;       ///< the interior leaves, ascending
  std::vector<BoundaryOctant> boundary;
  /// Per surface node (indexed like points): 0 plain, 1 on a feature line, 2 on a corner, 3
  /// pushed off a crowded feature line (BoundaryOctantOptions::off_line). Like the others, a
  /// push is undone (back to `unsnapped`) where it leaves an inverted element; unlike them the
  /// node is free in the dihedral optimiser.
  std::vector<std::uint8_t> snapped;
  std::vector<P3> unsnapped;               ///< position before feature snapping

  std::int32_t n_lattice() const { return static_cast<std::int32_t>(lattice.points.size()); }
};

struct BoundaryOctantStats {
  std::size_t n_free_faces = 0;
  std::size_t n_face_nodes = 0;      ///< lattice nodes on the free faces
  std::size_t n_surface_nodes = 0;   ///< distinct projections
  std::size_t n_shared_projections = 0;
  std::size_t n_next_normal = 0;     ///< projections that took a further local minimum
  std::size_t n_ray = 0;             ///< projections found along a free face's normal
  std::size_t n_blind = 0;           ///< inadmissible closest points kept (blind_closest)
  std::size_t n_unfolded = 0;        ///< backward projections replaced (unfold_backward)
  std::size_t n_corners_snapped = 0;
  std::size_t n_corners_missed = 0;
  std::size_t n_edge_snapped = 0;
  std::size_t n_pushed_off_lines = 0;  ///< unsnapped nodes moved off a crowded feature line
};

/// A place where the tree is too coarse for the construction, with the reason.
struct Problem3 {
  P3 where = P3::Zero();
  std::string what;
  /// The fix: drop the interior octants touching `where` (a face node that sees no admissible
  /// surface point: refining does not change the view, giving up the octants does), else refine.
  bool peel = false;
};

struct OctantComplexResult {
  OctantComplex complex;
  BoundaryOctantStats stats;
  std::vector<Problem3> problems;  ///< empty when the complex is complete
};

/// Drop interior octants so that the interior region is a manifold around every node of its
/// boundary: around each free-face corner the kept and the unkept ones among the eight octants
/// must each be face-connected. Returns how many octants were dropped. On n_threads threads
/// (the same octants dropped).
std::size_t remove_pinches(const Orthtree<3>& t, Flags& in, int n_threads = 1);

/// Drop interior octants so that no node of the interior region's boundary has free faces on
/// both sides along an axis (a staircase twisted around the node: kept and unkept octants each
/// face-connected, so not a pinch). No single projection of such a node leaves through both
/// faces, and one of their boundary octants folds (diagnose3d: 70 such nodes on spool's first
/// tree at level 6, none at level 5). Of the octants with those faces, the one whose centre is
/// nearest the surface (`depth_at` its centre: the distance to the surface) goes; up to 8
/// passes. Returns how many octants were dropped.
std::size_t remove_opposing(const Orthtree<3>& t, Flags& in, const std::function<double(const P3&)>& depth_at);

/// Keep the `n_keep` largest face-connected components of the interior octants, drop the others
/// (islands left in parts thinner than the octants would be extra solids). Returns how many
/// octants were dropped.
std::size_t keep_largest_components(const Orthtree<3>& t, Flags& in, int n_keep);

/// Whether the segment a -> b enters the interior octants `in` by more than the graze allowance
/// (BoundaryOctantOptions::graze, graze_region, graze_length): segment_enters_kept_region with
/// graze_region, else segment_enters_kept. The boundary octants' projections and the
/// untangling's moves both ask it.
bool enters_interior(const Orthtree<3>& t, const Flags& in, const P3& a, const P3& b, double graze, bool graze_region,
                     double graze_length);

/// Drop interior octants whose free faces come nearer the surface than `fraction` of their size.
/// The facets' distances on n_threads threads (the same octants dropped for any count).
/// With `whole_face`, only those whose free face lies that near the surface at all its corners
/// and its centre (a face flat on the surface; see Options3d::flat_buffer).
std::size_t apply_buffer(const Orthtree<3>& t, Flags& in, const SurfaceBoundary& s, double fraction, int n_threads = 1,
                         bool whole_face = false);

struct BoundaryOctantOptions {
  int max_normals = 4;               ///< local minima tried per node
  bool blind_closest = true;         ///< no admissible point: keep the closest one, not a Problem
  double graze = 0.05;               ///< a projection segment may cut this fraction of an interior octant's size
  /// The graze allowance only at the interior region's boundary (segment_enters_kept_region):
  /// a segment along a face between two interior octants is refused.
  bool graze_region = false;
  /// With graze_region: a segment running along an interior octant for more than this x its
  /// size enters it (0 = off; segment_enters_kept_region's graze_length).
  double graze_length = 0.0;
  /// With graze_region: a projection backward against a free face of its node (cosine with the
  /// face's outward normal at most -0.5) that runs along the interior octants (within the graze
  /// allowance, cells_along_kept) for more than this many octant sizes is refused (0 = off):
  /// the rim-edge case of rotor's sampled thickness try (branch rotor3), nodes under an
  /// overhang projecting along the interior region's own boundary. Off: no try sets it
  /// (docs/measurements.md, branch rotor4).
  double backward_along = 0.0;
  /// A projection must leave its node through one of the node's free faces: the cosine between
  /// the segment and that face's outward normal at least min_outward, and the cosine between the
  /// surface normal where it lands and that face's normal at least min_facing (-1 = no such
  /// rule). Closest points that run back along the interior octants or land on the far side of
  /// a part thinner than the octants fold their boundary octants; the next local minima and the
  /// rays along the free faces' normals are tried instead. Off by default: measured with 0.3 /
  /// 0.3, the inverted tetrahedra left after both untanglings on the first fandisk L4 tree went
  /// 18 -> 11 (still refused), sphere966 L4/L5, spool L4 and the CI-seed properties stayed valid,
  /// but anchor L5 went from valid (386976 tets, 26.7 s) to refused (177 inverted, 43.8 s).
  double min_outward = -1.0;
  double min_facing = -1.0;
  /// min_outward must hold for every free face of the node, not just one.
  bool outward_all_faces = false;
  bool rays = true;                  ///< try rays along the free faces' normals
  /// At a node with free faces along two or more axes (an edge or corner of the interior
  /// region), a closest point whose direction runs in the plane of one of those faces and back
  /// against none (its smallest cosine with their normals within +-this of 0; 0 = off) is
  /// replaced by the surface point along the sum of the faces' normals, where that one is
  /// admissible. Where the level changes along a flat face the interior octants' staircase has
  /// a step whose face stands square to the surface: the closest points of its nodes run in its
  /// plane and its boundary octant is flat. Measured (session 51, diagnose3d --snap --buffer 0,
  /// folded boundary octants of the first tree at level 6): an axis-parallel box 458 -> 0,
  /// flange 2923 -> 1842, bracket 1353 -> 234, fandisk 1957 -> 1196, anchor 812 -> 156,
  /// elephant 1355 -> 1356, sphere966 0 -> 0. Directions backward against a face are left
  /// alone: a first version that replaced every cosine under 0.01 (backward ones too) left
  /// elephant L4 invalid in the CLI.
  double in_plane_cosine = 0.0;
  /// Unfold backward projections (unfold_backward in boundary_octants.cpp): a surface node
  /// whose projection runs back against a free face of its face node (cos < 0) and folds cones
  /// of its boundary octants takes the other candidate (next local minima, rays) that folds
  /// fewest. Off by default: it halves the raw inverted tetrahedra of the first trees (diagnose3d,
  /// with snapping: rotor L6 24931 -> 11193, spool L6 11650 -> 7717; case 180 L3 196 -> 114)
  /// but the untangling leaves about as many behind, so regressions/voxel-seed5-case180 is still
  /// refused at level 3 through every try and spool L6 still fails its tries; at level 4 it
  /// changes meshes that were valid (anchor 12.73 -> 12.21 deg; elephant then valid only
  /// without feature snapping; spool 14.30 -> 14.54 deg). docs/measurements.md, session f1.
  bool unfold_backward = false;
  int n_threads = 1;                 ///< threads for the nodes and projections (the same result for any)
  bool snap_features = true;
  double corner_radius = 0.75;       ///< pull a corner onto a node within this many face sizes
  double edge_radius = 0.35;         ///< project nodes within this many face sizes onto a feature line
  /// Nodes left on a concave feature line (nearer than half this many face sizes) by the
  /// crowding rule move this far into the face they look at (0 = stay; not with min_facing,
  /// see push_off_lines). At a concave feature edge the closest points of all the lattice nodes
  /// in the wedge are on the line; snapping keeps them 0.3 face sizes apart, and the ones it
  /// leaves there make interface caps (177-179 deg) between the snapped ones, whose
  /// tetrahedra no node move can mend (any move of a cap's free node folds its other cap).
  /// Measured on the final meshes: spool L4's 4 tetrahedra under 10 deg (2.6 deg) and one of
  /// anchor L4's two places under 10 deg (8.3 deg) stood on such caps.
  double off_line = 0.3;
  /// A push is tried only where a surface face of the octants around the node has an angle
  /// below this (degrees; nearly all crowded nodes have one: 27 of 28 pushes on fandisk L4's
  /// first tree without the buffer rule) and kept only if it raises that angle and folds none
  /// of the octants' cones.
  double off_line_below_deg = 10.0;
};

OctantComplexResult build_octant_complex(const Orthtree<3>& t, const Flags& in, const SurfaceBoundary& s,
                                         const BoundaryOctantOptions& opt = {});

/// First surface point on the segment q..end (Moller-Trumbore against the triangles on it), or
/// false.
bool first_hit(const SurfaceBoundary& s, const P3& q, const P3& end, P3& hit);

/// The ring of a free face: its corners in FaceCorners<3> order with the lattice nodes at edge
/// midpoints in between; corner_slot receives each corner's position.
std::vector<std::int32_t> face_ring(const LatticeNodes<3>& nodes, const Cell<3>& cell, int face,
                                    std::array<std::uint8_t, 4>& corner_slot);

}  // namespace febemesh::dim3
