#pragma once
// The paper's general algorithm generalised to 3D (its conclusion: boundary octants between
// the interior octants and the surface): octree by the level field, 2:1 balance, interior
// octants (buffer and pinch rules), boundary octants by projection, feature snapping, the
// tetrahedra from templates, guarded smoothing, the BE mesh.
// Where the construction finds the tree too coarse (no admissible projection, an inverted
// element), the octants around the place are refined and the construction is redone, up to
// the maximum level.

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/orthtree.hpp"
#include "core/quality.hpp"
#include "core/sized_level.hpp"
#include "core/stage_timer.hpp"
#include "core/validate.hpp"
#include "dim3/boundary_octants.hpp"
#include "dim3/hex_dominant.hpp"
#include "dim3/planar_frame.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/templates3d.hpp"

namespace febemesh::dim3 {

struct Options3d {
  int level = 4;                     ///< global level at the surface
  /// The octants' side at the surface in the surface's units (0: by `level`). mesh3d then meshes
  /// at the level whose octants in the default root cube are no larger (core level_for_size) and
  /// enlarges the root cube by less than 2x (SurfaceOptions::root_scale) so that they have this
  /// side; the curvature, feature and thickness levels follow the root cube.
  double size = 0.0;
  int extra_levels = 2;              ///< curvature/feature refinement above `level`
  int smoothing_iterations = 4;      ///< the paper recommends about four
  double buffer = 0.2;               ///< drop interior octants nearer the surface than this x size
  /// Drop interior octants whose free face lies nearer the surface than this x size at all its
  /// corners and its centre (apply_buffer's whole_face; 0 = off). For the tries without the
  /// buffer rule: a face flat on the surface (rotor's rim, x 0.22581, lies 0.00022 above a
  /// lattice plane: 0.05 of a level-8 octant, 0.11 of a level-9 one) makes a flat boundary
  /// octant, and its neighbours' side faces have corners whose projections run along the face
  /// (cos 0), into tetrahedra of no volume that the untangling cannot open and that refining
  /// keeps (the plane is a lattice plane of every finer level).
  double flat_buffer = 0.0;
  bool snap_features = true;
  /// Drop interior octants at nodes with free faces on both sides along an axis
  /// (remove_opposing), after the pinch rule. Off: measured (CLI, L4, one thread, tets / min
  /// dihedral) elephant 1172412 / 13.80 -> 1187662 / 17.04 deg, anchor 276042 / 12.73 ->
  /// 275610 / 12.72, rotor 68398 / 16.73 -> 76936 / 16.94, but fandisk 180486 / 13.18 ->
  /// 271352 / 12.52 in 19.7 s CPU instead of 11.5; sphere966 and spool byte-identical (none
  /// there). Spool L6 without the buffer rule is still refused (diagnose3d --pipeline: raw
  /// inverted tets of the first tree 2503 -> 1888, the repairs end with 158-171 problems at the
  /// same place as without it).
  bool drop_opposing = false;
  /// Snap to features only when at most this share of the feature lines' ends are free ends
  /// (Features::free_end_share): above it the "features" are facet creases of a faceted skin,
  /// and snapping pins nodes at their ends into flat slivers (elephant.off: 1.6 deg). 1 keeps
  /// snapping always. Result3d::features_dropped reports it.
  double faceted_free_ends = 0.5;
  /// When the run with the buffer rule fails, run once more without it (Result3d::buffer_dropped).
  bool retry_without_buffer = true;
  /// The try without the buffer rule first, then the one with facing projections, and the one
  /// with the buffer rule only when both are refused (Result3d::buffer_fallback), instead of the
  /// buffer rule's try first (then without it, then facing). In the L4/L5 runs of the shared
  /// surfaces the buffer rule's try stood only on sphere966 and anchor L5, where the try without
  /// it makes a mesh as good; elsewhere it was refused, at up to a third of the run (fandisk L5
  /// 5.6 of 28 s, spool L5 6.8 of 9.2 s, elephant L4 9.5 of 27.5 s). Measured:
  /// docs/measurements.md, session 31. Off: the order before (mesh3d --buffer-first).
  bool buffer_last = true;
  bool peel = false;                 ///< drop the octants at blind face nodes instead of refining
  /// When the untangling leaves inverted tets or folded interface triangles, drop the interior
  /// octants at the lattice nodes behind them (thicker boundary octants) up to this many times
  /// per tree before refining around them.
  int peel_rounds = 0;
  /// When the untangling leaves folded interface triangles but no inverted tetrahedron, smooth
  /// and keep the mesh if the validator accepts it, else refine around the folds.
  bool accept_valid_folds = false;
  /// When every other try fails, run once more without the buffer rule, with projections that
  /// leave through every free face of their node and land on surface facing it (min_outward and
  /// min_facing 0.3, outward_all_faces) and accept_valid_folds (Result3d::facing_projection).
  bool retry_facing = true;
  /// On a surface that is not faceted (faceted_free_ends), every try with feature snapping (with
  /// the buffer rule, without it, with facing projections) before any without it, instead of
  /// each try once more without snapping at once (Result3d::features_dropped then means all the
  /// tries with it were refused). In the sweep of the shared surfaces no try without snapping
  /// made a mesh after one with it was refused, so those refusals were spent for nothing; now
  /// they come last. Measured (docs/measurements.md, session 29): the same mesh.msh on 30 CLI
  /// runs of the bar (levels 4-6, tet and hex) and the same counts, angle and volume error on
  /// spool L6 (tet, hex) and rotor L6; CPU 362.9 -> 279.7 s over 20 of them (spool L5 27.1 ->
  /// 9.4 s, fandisk L6 76.1 -> 45.6 s); the 3D property suite and 440 torus and voxel survey
  /// cases valid. A mesh changes only where a try with snapping now stands before one without
  /// it would have.
  bool features_fallback_last = true;
  /// Where a round of the untangling's surface node moves leaves the complex as it was (every
  /// node moved back to its own point), the rounds after it, up to the last, would repeat it bit
  /// for bit: they are skipped, with the same mesh and counts (untangle3d's complex_unchanged).
  /// Off only to check that (tests/dim3/test_pipeline3d.cpp).
  bool skip_repeated_rounds = true;
  double graze = 0.05;               ///< projection segments may graze interior octants by this x size
  /// BoundaryOctantOptions::graze_region and graze_length, for the untangling's moves too. Off:
  /// no try sets them (measured on rotor's sampled thickness try, docs/measurements.md, branch
  /// rotor3: graze_region took its last places from 9 in three spots to 6-10 at the rim's edge;
  /// graze_length 0.5 on top of it doubled the first tree's problems).
  bool graze_region = false;
  double graze_length = 0.0;
  /// Where the untangling leaves inverted tetrahedra or folded interface triangles, refine
  /// around the cells they came from and the lattice nodes behind them (their own and the face
  /// nodes projecting onto their surface nodes) instead of their centroids: the untangling can
  /// drag a template node far from its cell (rotor's sampled thickness try, branch rotor3: a fan
  /// centre 171 octants away), and the centroids then lie far from the fault. Off: no try sets
  /// it (docs/measurements.md, branch rotor4).
  bool repair_at_cells = false;
  double backward_along = 0.0;  ///< BoundaryOctantOptions::backward_along (off: see there)
  /// The untangling's moves of nodes off the surface (lattice and template nodes) stay within
  /// the bounding box of their cells as built, grown by this x the cells' size; 0 = unbounded.
  /// Off: no try sets it (docs/measurements.md, branch rotor4).
  double untangle_reach = 0.0;
  /// Projection admissibility (BoundaryOctantOptions min_outward, min_facing, outward_all_faces).
  double min_outward = -1.0;
  double min_facing = -1.0;
  bool outward_all_faces = false;
  bool projection_rays = true;
  bool unfold_backward = false;      ///< BoundaryOctantOptions::unfold_backward (off: see there)
  /// BoundaryOctantOptions::in_plane_cosine (0 = off). Off but in the try with the surface at
  /// one level (uniform_in_plane_cosine): on in every try, it changed the shared surfaces'
  /// meshes (session 51, tet L4-6: all valid and at 15 deg or more but spool L6, refused after
  /// 494 s instead of valid; anchor L6 19.29 -> 16.03 deg; gear L6 4.7 M tets in 279 s).
  double in_plane_cosine = 0.0;
  int untangle_rounds = 4;            ///< rounds of moving surface nodes of inverted tets
  int untangle_sweeps = 30;          ///< node-by-node untangling sweeps (tet_optimize)
  int escobar_sweeps = 100;          ///< last-resort untangling sweeps by the Escobar objective (0 = none)
  int optimize_sweeps = 16;          ///< node-by-node dihedral-angle sweeps after smoothing
  double target_dihedral_deg = 30.0; ///< nodes whose tets all reach this angle are left alone
  /// In those sweeps, nodes snapped onto a feature line slide along it (else they stay put).
  bool slide_feature_nodes = true;
  /// After those sweeps, edges of tetrahedra under this angle (degrees) are removed where
  /// that raises the worst angle around them (dim3/edge_removal.hpp), then one more sweep
  /// pass; up to three rounds while edges go. 0 = none. With hex_dominant the cells whose
  /// tetrahedra it changed stay tetrahedra (TetMesh::cells_changed).
  double remove_edges_below_deg = 30.0;  // the sweeps' target_dihedral_deg
  /// In those rounds, tetrahedra still under this angle (degrees) where no removal helps try
  /// contracting a short edge (EdgeRemovalOptions::contract_below_deg; nodes are removed, and
  /// with hex_dominant their cells stay tetrahedra). 0 = none.
  double contract_edges_below_deg = 15.0;
  int max_repairs = 12;              ///< local refinements when the construction needs them
  /// Repairs that may leave more problems than the tree before them: a try stops at the next
  /// one that does ("the last one made it worse"). Refining around inverted tetrahedra moves
  /// the folds, so the count is noisy on the way down (fandisk L5's last try: 54 50 49 47 33
  /// 25 35, then valid). 0 for the tries that have another try after them (their meshes stay
  /// the same); retry_facing's last try has 1.
  int worse_repairs = 0;
  /// Refinements of the octants on the surface when thin parts fall apart (islands dropped or
  /// the wrong Euler characteristic).
  int topology_refinements = 2;
  /// Those refinements only while the tree has no interior octant at all (the thin retry,
  /// thin_retry_options: on a tree with interior octants they multiply the octants, rotor L4
  /// 37,927 -> 116,145 -> 311,522 over the repairs; without any, a plate thinner than the
  /// octants at the thickness level's cap has nothing to mesh).
  bool surface_refinements_empty_only = false;
  /// Opt-in (0, the default: off). For a wrong Euler characteristic, refine only the octants on
  /// the surface within reach of the surface the BE mesh misses (dim3/missed_surface.hpp:
  /// samples farther from the interface triangles than this x the side of the octant they lie
  /// in), and all of them only where no sample is that far. elephant L4 refines all 8,686 for
  /// an Euler characteristic one off (-1, expected -2; 604,226 -> 1,146,084 tetrahedra).
  double topology_gap = 0.0;
  /// Refinements around the octants dropped as islands, before the boundary octants are built:
  /// every leaf within `island_cells` of their size of an island octant is split, so that the
  /// thin part they sit in (elephant's legs, trunk, tail at level 4) gets interior octants that
  /// reach the rest. Not counted in max_repairs; trees without islands are untouched.
  int island_refinements = 3;
  double island_cells = 2.0;
  /// With an island refinement, also split the octants on the surface whose triangles are
  /// thinner (SurfaceBoundary::centroid_thickness) than this x their size; 0 = off.
  double thin_cells = 1.5;
  /// An island refinement that would split more than this share of the leaves is tried once
  /// per run and kept only if no island is left (a tube two octants thick: resolved; rotor's
  /// blades at levels 4 and 5: islands left, the tree before it stays), and then the octants on
  /// the surface are not all refined for islands either (topology_refinements).
  double island_max_fraction = 0.12;
  /// Octants wanted across the solid's thickness (SurfaceBoundary's thickness level, 0 = off),
  /// up to level + thickness_extra_levels.
  double thickness_cells = 0.0;
  int thickness_extra_levels = 2;
  /// When the mesh is valid but its volume error exceeds thin_retry_error (parts thinner than
  /// the octants are lost), run once more with thickness_cells = thin_retry_cells and without
  /// the buffer rule, and keep that mesh if it is valid and loses less (Result3d::
  /// thickness_refined). 0 = off; not with thickness_cells > 0. The retry is bounded: at most 4
  /// repairs per try and 8x the first tree's octants (1M at least); past them the first mesh stands.
  double thin_retry_cells = 2.0;
  double thin_retry_error = 0.05;
  /// The retry also where the volume error is below thin_retry_error but the input surface
  /// gets farther than this many octants of the level from the BE mesh (surface_to_be_distance)
  /// and part of the solid is thinner than thin_retry_cells of them: a thin part of little
  /// volume left out (a cone's tip). Its mesh then stands when it is valid, gets nearer and
  /// loses no more than thin_retry_error or the first mesh. 0 = off. Measured (surface_to_be
  /// over the octant side, CLI): 0.06-1.17 on the shared surfaces and the parts at levels 4-5,
  /// 0.07-0.76 at level 6 (rotor L4 4.88, retried by its volume). Cones 2 high, r 0.4 and 0.6
  /// (Gmsh STL, CLI, two threads, 7 runs at levels 4-6): the retry ran in 6 and stood in 3 (r
  /// 0.4 at level 5: the tip 8.25 -> 2.10 octants short, 4.05% -> 0.78% of the volume lost,
  /// 16,718 -> 154,409 tets, 1.8 -> 9.7 s; r 0.6 at level 6: 3.14 -> 1.33 octants, 1.3 -> 2.8
  /// s); in the other 3 its tries were refused at the base's 73 deg rim, 4.0-6.0 s more each.
  double thin_retry_gap = 2.0;
  /// The retry's own work bound (`effort` for it, without min_effort_octants): it only improves
  /// a valid mesh, so it gets less room than the first run (rotor L4: its 3 tries on 198k-313k
  /// octants cost 190 s CPU on top of the first run's 70 s, and lost as much volume).
  double thin_retry_effort = 10.0;
  /// When every try is refused (GeometryError or LimitError) and part of the solid is thinner
  /// than this many octants of level + 1 (where the thickness level passes the feature level),
  /// run once more with this many octants across every part (thickness_cells) from the first
  /// tree, up to level + thickness_extra_levels, without the buffer rule and within its own
  /// work bound of thin_retry_effort (Result3d::thickness_after_refusal). 0 = off. Boundary
  /// octants fold where a sheet is 1-3 octants thick: its face nodes lie nearer the far sheet,
  /// and refining around the folds moves them along a taper. Measured (spool L6, whose right
  /// flange's lip tapers from 0.022 to 0.010, 1-3 level-7 octants: refused after 795 s CPU):
  /// with 4 octants across, up to level 8, the first try is valid without a repair (diagnose3d
  /// --single --buffer 0: 3,186,715 tets, 11.05 deg, 0.16% volume error, 32 s CPU, 737 MB).
  /// Not run where thickness_probe built its first tree and it did not stand (Effort::
  /// thickness_probe_refused): the coarse try below comes next.
  double refused_thickness_cells = 4.0;
  /// Where that try would run (thin parts, as for refused_thickness_cells) and the run's first
  /// tree leaves problems after its untangling, the first tree of that try is built at once,
  /// without a repair (its options, thickness_try_options): when its mesh has no problem and
  /// passes the validator, it stands (Result3d::thickness_early), else the run goes on from its
  /// own first tree as without this. Measured (spool L6, CLI, one thread): every try was
  /// refused after 339 s, then that try stood at its first tree (374 s wall in all); now the
  /// same mesh.msh in 35 s wall (28 s CPU). The thickness level's first trees of anchor L4,
  /// elephant L4-L6 and fandisk L4-L6 have problems, so their meshes stay the same, at the
  /// probe's cost (0.0-0.6 s CPU with first_round_inverted_share's early end).
  bool thickness_probe = true;
  /// The probe's early end: a try whose first tree's first round of untangling leaves more than
  /// this share of its tetrahedra inverted at the templates is refused there (GeometryError); 0 =
  /// off (every try but the probe). Measured (first rounds at the thickness level): spool L6
  /// 16106 -> 19 (0.1%, it stands); anchor L4 34%, fandisk L4 6%, fandisk L5 8%, elephant L4 5%
  /// (all refused after their nine rounds and the Escobar pass). Not a rule for the thin retry
  /// (thin_retry_cells): at 2% (8%) its tries ended early on rotor L5 (60 -> 17 s CPU, the same
  /// mesh), but 30 (19) of the 35 retries that stood in 200 voxel survey cases (seed 4) were lost.
  double first_round_inverted_share = 0.0;
  /// When that try is refused too (or not run), once more without what refines the thin parts
  /// to 1-3 octants across: no feature level (SurfaceOptions::feature_extra_levels 0: on a
  /// coarse tessellation the triangles touching a feature edge cover whole thin sheets), no
  /// island refinements and no thin-surface refinement, within its own work bound of
  /// thin_retry_effort (Result3d::thin_parts_coarse). Parts thinner than the octants are then
  /// not meshed (the volume error and a warning say how much). Measured (rotor L6, whose blades
  /// are 0.02 thick, 1.2 level-6 octants: refused by every other try after 1389 s CPU; this try
  /// alone, diagnose3d --feature-extra 0 --thin-cells 0 --island-refinements 0 --pipeline):
  /// valid, 162,253 tets, 20.01 deg, 30.36% of the volume (the blades) lost.
  bool coarse_thin_after_refusal = true;
  /// When every try at the level is refused (those of the thickness level and with the thin
  /// parts coarse too, where they apply), once more with the surface at that one level:
  /// extra_levels 0 (no curvature or feature level), within its own work bound
  /// (uniform_try_options, Result3d::surface_uniform); the lattice draws after such a run start
  /// there. Where the level changes along the surface the interior octants' staircase has steps
  /// whose faces stand across the surface, and their boundary octants fold; the repairs refine
  /// around the folds and add more steps. Measured (session 51, CLI, one thread):
  /// examples/3d/flange.stl level 6, refused after 260 s through every try and lattice draw,
  /// was valid at --extra-levels 0 in 13 s (457,574 tets, 22.99 deg), and is valid with this
  /// try in 69.5 s (457,543 tets, 27.11 deg); the block is valid at levels 4-6 (refused or
  /// invalid before), the tee at level 6 (15.17 deg, 232 s).
  bool uniform_after_refusal = true;
  /// On a faceted surface (faceted_free_ends), that try (uniform_after_refusal) comes right
  /// after the first try is refused, before the facing projections' and the buffer rule's
  /// tries with the curvature and feature levels, and is not run again at the end; where it is
  /// refused too, the tries go on in their order. Only in a run's own chain of tries (not in
  /// the thickness, thin-parts-coarse or thin retries). A faceted surface's feature lines are
  /// not snapped to, and the levels' steps along its flat faces fold the first tree: the
  /// parts' first trees at level 6 had 8,496 (block) and 15,201 (flange) raw inverted
  /// tetrahedra with the levels and 463 (block) at the one level, whose try stood where those
  /// with the levels were refused after 68 s (block L6; session 52). Off: the order of session
  /// 51 (mesh3d --uniform-last).
  bool uniform_early_faceted = true;
  /// On a surface whose feature lines are snapped to, that try comes after every try with
  /// snapping is refused, before the tries without it (features_fallback_last). Off: an
  /// experiment (mesh3d --uniform-before-unsnapped). Measured (session 52, CLI, one thread,
  /// beside the CI run): examples/3d/tee.stl level 6 the same mesh in 139 s CPU (197 s in the
  /// parts sweep without it); rotor L6 the same mesh in 666 s CPU (569-712 s before): its
  /// one-level try ran about 300 s and was refused, and the tries without snapping after it
  /// stopped at once at the work bound. Not the default: fandisk L5 in the cube's 24
  /// orientations stood at one level in 17 of them, 57,600 tets and 1.9-2.7% of the volume lost,
  /// where the tries without snapping stand by default with 244,372-767,148 tets and 0.22-0.61%.
  bool uniform_early_snapped = false;
  /// in_plane_cosine in that try: there the level no longer changes along the surface, and
  /// its steps are those of the thickness level and the repairs (examples/3d/block.stl level 6
  /// stood there with it, session 51).
  double uniform_in_plane_cosine = 0.01;
  int max_level = -1;                ///< no octant finer than this; -1 = level + extra_levels + 2
  std::size_t max_cells = 20000000;  ///< refuse larger trees (LimitError)
  /// The work bound, so that no input runs for ever: the octants of every tree the boundary
  /// octants are built on add up, over all the tries of one run (the thickness retry has its
  /// own count), to at most `effort` times the first tree's (`min_effort_octants` at least).
  /// Past it the last valid mesh of the try stands, or LimitError. A build costs about the same
  /// per octant on every try, so `effort` is about the run's cost in first builds.
  double effort = 60.0;
  std::size_t min_effort_octants = 2000000;
  /// When every try is refused after building on fewer than min_effort_octants octants (a
  /// coarse level for the shape), mesh3d tries up to this many levels finer, each within
  /// min_effort_octants octants (Result3d::level_raised). 0: refuse instead. With lattice draws
  /// the first run's raise comes after them (in the frame of the planar faces, after the
  /// frame's draw and the given axes' run), and only when no run at the level asked stands
  /// undegraded (a raised mesh is degraded).
  int raise_levels = 1;
  /// Mesh in the frame of the surface's planar faces when it puts 10% more of the area on
  /// planes square to an axis than the given axes do (dim3/planar_frame.hpp), and turn the mesh
  /// back: a machined part given at an angle is meshed as if given aligned. Surfaces without
  /// such faces (elephant, sphere966) and aligned parts are meshed in their own axes, unchanged.
  /// When the frame's mesh is degraded (lattice_draws below), the frame gets one lattice draw,
  /// then the run is made in the given axes (Result3d::frame_refused), and the mesh ranked first
  /// there stands.
  bool align_planar_faces = true;
  /// Lattice draws: where the mesh is degraded (refused; one level finer than asked; the thin
  /// parts left out; only the buffer rule's try stood; a dihedral angle under
  /// draw_min_dihedral_deg; more of the volume lost than draw_max_volume_error) the run is
  /// made again, up to this many times, with the root cube shifted against the surface
  /// (lattice_draw_shift). The first mesh that is not degraded stands; when none is, the valid
  /// one that loses the least volume (Result3d::lattice_draw). A mesh at the level asked stands
  /// over one degraded otherwise even where it loses more volume. Which tries fail depends on
  /// where the lattice planes cut the part: fandisk turned 180 degrees about x (the lattice
  /// turns with it) is meshed at level 5 only with its thin parts left out, and at 15 degrees
  /// with the root shifted by a hundredth of its side. A draw runs the tries at the level asked
  /// within what the runs before it left of the work bound (Options3d::effort), without the
  /// fallbacks after a refusal. For a part meshed in the frame of its planar faces the second
  /// run is the frame's draw, the third the given axes (with a work bound of their own).
  /// 0: one lattice, as before session 34.
  int lattice_draws = 2;
  /// The smallest dihedral angle (degrees) of a mesh that is not degraded for the draws. 15
  /// makes every orientation of fandisk and spool at level 5 reach 15, at up to 30x the time of
  /// a run (README, "Lattice draws").
  double draw_min_dihedral_deg = 10.0;
  /// The share of the surface's volume a mesh may lose and not be degraded for the draws. Where
  /// parts thinner than the octants are not meshed, the lattice decides how much of them is:
  /// rotor at level 4 loses 29.6% on the first lattice and 22.7% on draw 1 (session 35). The
  /// other surfaces of the bar lose 3.3% at most. Not 5%: coarse meshes of thin curved parts
  /// lose 5-10% by their resolution alone (85 of 200 tori of the survey at level 3, seed 11),
  /// where the draws gained a point for 66% more time.
  double draw_max_volume_error = 0.10;
  /// Where the first run of the axes is valid and degraded by its lost volume only, its draws
  /// build on at most this times the octants that run built (Effort::used), shared as the work
  /// bound is (0: no such bound; CLI --draw-effort). Such a draw only looks for a lattice that
  /// keeps more of the thin parts. Rotor (session 36, one thread, CPU s): at level 4 draw 1
  /// builds 1.03x the first run's octants and keeps 22.74% lost instead of 29.63% (draw 2 then
  /// stops at once: 12.7 -> 6.6 s, the same mesh); at level 5 the tetrahedral run's draw 1
  /// built 4.8x (3.58 M octants) and ended at the work bound without a mesh (the same mesh,
  /// 184 -> 86 s), the hex-dominant run's 4.4x and kept 22.27% instead of 28.94% (with the
  /// bound: 28.94%, 264 -> 85 s).
  double volume_draw_effort = 2.0;
  /// Where the mesh that stands is valid and its smallest dihedral angle is under this
  /// (degrees; 0: never), one more run on its lattice with flat_buffer at flat_retry_buffer
  /// (within the octants it built, no level raise, no thin-part retry, no mesh after a
  /// refusal); that mesh stands if it ranks no worse, loses no more than draw_max_volume_error
  /// or the first's volume, and its smallest angle is larger. A flat face a little above a lattice plane leaves interior octants whose free faces lie on it,
  /// flat boundary octants whose slivers no node move mends (spool L5 o22: an interior node
  /// 0.0012 under a face, two tetrahedra at 11.75 deg; 16.79 with the flat buffer). On every try
  /// the flat buffer costs thin parts and time (docs/measurements.md, session 36), so it is a
  /// retry. Every mesh of the bar's table is at 15 deg or more: none retries.
  double flat_retry_below_deg = 15.0;
  double flat_retry_buffer = 0.25;
  int n_threads = 1;
  bool hex_dominant = false;         ///< --elements hex: regroup the final tets (hex_dominant.hpp)
  HexDominantOptions hex;
};

using StageTime3 = StageTime;

struct Result3d {
  Orthtree<3> tree;                  ///< final tree (after repairs)
  Flags interior;                    ///< interior octants after buffer and pinch rules
  TetMesh fe;                        ///< smoothed FE mesh + BE mesh
  BoundaryOctantStats stats;
  std::size_t n_leaves_subdivided = 0;
  std::size_t n_buffer_dropped = 0;
  std::size_t n_pinches_dropped = 0;
  std::size_t n_opposing_dropped = 0;  ///< interior octants dropped by remove_opposing
  std::size_t n_islands_dropped = 0;  ///< interior octants outside the largest components
  std::size_t n_untangled = 0;       ///< surface node moves that unfolded inverted tets
  std::size_t n_peeled = 0;          ///< interior octants dropped around blind face nodes
  std::size_t n_snaps_reverted = 0;  ///< feature snaps undone because they inverted an element
  int n_repairs = 0;
  std::size_t n_octants_built = 0;   ///< octants of every tree built on, over all tries (Options3d::effort)
  bool buffer_dropped = false;       ///< the run with the buffer rule failed; this one is without
  bool buffer_fallback = false;      ///< Options3d::buffer_last: the runs without the buffer rule failed; this one has it
  bool features_dropped = false;     ///< the run with feature snapping failed; this one is without
  bool facing_projection = false;    ///< the runs above failed; this one has Options3d::retry_facing's rules
  bool thickness_refined = false;    ///< lost volume; this run has Options3d::thin_retry_cells' thickness level
  bool thickness_after_refusal = false;  ///< refused; this run has Options3d::refused_thickness_cells' thickness level
  bool thin_parts_coarse = false;    ///< refused; this run has Options3d::coarse_thin_after_refusal's rules
  bool surface_uniform = false;      ///< refused; this run has Options3d::uniform_after_refusal's one level
  bool thickness_early = false;      ///< the first tree had problems; this run is Options3d::thickness_probe's tree
  int level = 0;                     ///< the level asked for: Options3d::level, or the one Options3d::size gave
  double root_scale = 1.0;           ///< SurfaceOptions::root_scale of the run (Options3d::size)
  double cell_size = 0.0;            ///< the octants' side at the surface at `level`: the root cube's side / 2^level
  int level_raised = 0;              ///< refused at the level asked; meshed this many levels finer (raise_levels)
  std::vector<Problem3> repaired;    ///< what the repairs were for
  std::size_t n_smoothing_accepted = 0, n_smoothing_rejected = 0;
  std::size_t n_untangle_moves = 0;  ///< node moves of the untangling (tet_optimize)
  std::size_t n_optimize_moves = 0;  ///< node moves of the dihedral-angle optimisation
  std::size_t n_edges_removed = 0;   ///< edges removed after it (remove_edges_below_deg)
  std::size_t n_edges_contracted = 0;  ///< edges contracted there (contract_edges_below_deg)
  std::size_t n_concave_swaps = 0;  ///< of the edges removed, concave surface edges (EdgeRemovalOptions::concave_below_deg)
  HexDominantStats hex;              ///< with opt.hex_dominant
  /// The frame meshed in (Options3d::align_planar_faces); with that option off, not turned, but
  /// share_frame says what the frame would have put on its planes.
  PlanarFrame frame;
  bool frame_refused = false;        ///< the frame's tries were refused at the level asked; this run is in the given axes
  /// Options3d::lattice_draws: 0 = the first lattice; k = the lattice shifted by
  /// lattice_draw_shift(k) (the root cube's side times it).
  int lattice_draw = 0;
  int lattice_draws_run = 0;         ///< runs made after the first (draws; the given axes after a frame), whichever stands
  bool flat_retry_made = false;      ///< Options3d::flat_retry_below_deg: the retry with the flat buffer was made
  bool flat_retry = false;           ///< ... and its mesh stands
  std::vector<StageTime3> times;
  /// validate(fe.mesh, surface_validation(s)) where the pipeline made it of the mesh it returns
  /// (after the Escobar pass, with folds pending, the thickness retry), with content_hash of
  /// that mesh: a caller finding the same hash has the report without validating again.
  std::optional<ValidationReport> validation;
  std::uint64_t validation_hash = 0;
  /// summarize_quality(fe.mesh, 10, n_threads) where mesh3d took it (to rank lattice draws),
  /// with content_hash of that mesh: a caller finding the same hash has it without a second
  /// pass (sphere966 L6: 0.3-0.4 s of one thread).
  std::optional<QualitySummary> quality;
  std::uint64_t quality_hash = 0;
};

using Progress3 = std::function<void(const std::string&)>;

/// Runs the whole pipeline; throws GeometryError when a repair would exceed max_level and
/// LimitError when the tree would exceed max_cells. `s` gets the options' levels. The tries, in
/// order (Options3d::buffer_last): without the buffer rule; with facing projections
/// (Options3d::retry_facing, Result3d::facing_projection); with the buffer rule
/// (Result3d::buffer_fallback). Without buffer_last: with the buffer rule; without it
/// (Result3d::buffer_dropped); with facing projections. All of them with feature snapping first,
/// then all without (Options3d::features_fallback_last, Result3d::features_dropped); when those
/// are refused cheaply, all of it one level finer (Options3d::raise_levels; after the lattice
/// draws, Options3d::lattice_draws).
Result3d mesh3d(SurfaceBoundary& s, const Options3d& opt, const Progress3& progress = {});

/// The optimisation's aim (the CLI's --target-dihedral): the node sweeps' target_dihedral_deg and
/// the edge removal's bar; contraction stays for the tetrahedra under 15 deg, or under the aim
/// when that is lower.
inline void set_target_dihedral(Options3d& opt, double deg) {
  opt.target_dihedral_deg = deg;
  opt.remove_edges_below_deg = deg;
  opt.contract_edges_below_deg = std::min(Options3d{}.contract_edges_below_deg, deg);
}

/// The root cube's shift of lattice draw k (1, 2; Options3d::lattice_draws), in shares of its
/// side (SurfaceOptions::root_shift); zero for k = 0.
P3 lattice_draw_shift(int k);

/// The buffer rules of opt on the interior octants `in`: Options3d::buffer, then flat_buffer
/// where it reaches farther (apply_buffer's whole faces). Returns how many octants they dropped.
std::size_t apply_buffer_rules(const Orthtree<3>& t, Flags& in, const SurfaceBoundary& s, const Options3d& opt);

/// The options of mesh3d's last try when every other fails (Options3d::retry_facing): `opt`
/// without the buffer rule, with facing projections only, accept_valid_folds, one repair that
/// makes things worse allowed, and no further retry.
Options3d facing_try_options(const Options3d& opt);

/// The options of the try with the thickness level (Options3d::refused_thickness_cells octants
/// across the thin parts, up to level + thickness_extra_levels): `opt` without the buffer rule
/// (its one-octant slabs in thin parts project through them), no level raise, its own work
/// bound of thin_retry_effort first trees.
Options3d thickness_try_options(const Options3d& opt);

/// The options of the thin retry (Options3d::thin_retry_cells octants across the thin parts,
/// up to level + thickness_extra_levels) after a run at `ran` whose first tree had
/// `first_tree_leaves` leaves: no buffer rule, the surface refined only while the tree has no
/// interior octant (surface_refinements_empty_only), at most 4 repairs a try, trees of at most
/// 8x the first tree's leaves (2^20 at least), its own work bound of thin_retry_effort.
Options3d thin_retry_options(const Options3d& ran, std::size_t first_tree_leaves);

/// The options of the thin parts' try at a first tree without an interior octant
/// (Options3d::thickness_probe): thin_retry_options, with the thickness level's cap at the level
/// that puts thin_retry_cells octants across the thin parts (SurfaceBoundary::thin_parts_level;
/// level + thickness_extra_levels at least, 4 levels more at most), two levels of repairs below
/// it, and the run's min_effort_octants.
Options3d thin_parts_try_options(SurfaceBoundary& s, const Options3d& opt, std::size_t first_tree_leaves);

/// The options of the try with the surface at one level (Options3d::uniform_after_refusal):
/// extra_levels 0, no level raise, in_plane_cosine uniform_in_plane_cosine.
Options3d uniform_try_options(const Options3d& opt);

/// Is part of the solid thinner than Options3d::refused_thickness_cells octants of level + 1
/// (where the thickness level passes the feature level, so that the thickness try's first tree
/// is not the plain one)? False when refused_thickness_cells is 0.
bool thickness_try_applies(SurfaceBoundary& s, const Options3d& opt);

/// "N octants across", N as short as %g prints it (4, 2.5): the thickness tries' messages.
std::string octants_across(double cells);

/// What a mesh of `s` is validated against (DESIGN.md, "Validity"): the solid's Euler
/// characteristic is half the surface's (when that is even), and interface nodes lie on the
/// surface within 1e-10 of its diagonal. The options refer to `s`, which must outlive them.
/// On n_threads threads (the same report on any count).
ValidateOptions<3> surface_validation(const SurfaceBoundary& s, int n_threads = 1);

/// The validator's report of r.fe.mesh with surface_validation(s, n_threads): the pipeline's own
/// when r carries one of this mesh (Result3d::validation and its content hash), else validated
/// now; r carries it afterwards (the CLI then does not validate again).
const ValidationReport& validation_of(Result3d& r, const SurfaceBoundary& s, int n_threads);

}  // namespace febemesh::dim3
