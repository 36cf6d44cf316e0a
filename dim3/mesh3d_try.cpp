#include "dim3/mesh3d_try.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/local_repair.hpp"
#include "core/validate.hpp"
#include "dim3/faults3d.hpp"
#include "dim3/missed_surface.hpp"
#include "dim3/quality_stage3d.hpp"
#include "dim3/triangle_predicates.hpp"
#include "dim3/untangle3d.hpp"

namespace febemesh::dim3 {
namespace {

/// Drops the kept leaves touching any of `points`; returns how many.
std::size_t peel(const Orthtree<3>& t, Flags& in, const std::vector<P3>& points) {
  std::size_t n = 0;
  for (const P3& p : points) {
    Box<3> b;
    b.lo = p.array() - 1e-9 * t.unit();
    b.hi = p.array() + 1e-9 * t.unit();
    for (std::size_t j : leaves_in_box(t, b))
      if (in[j]) in[j] = 0, ++n;
  }
  return n;
}

/// Volume of the leaves kept `before` keep_largest_components and dropped by it (`after`).
double island_volume(const Orthtree<3>& t, const Flags& before, const Flags& after) {
  double v = 0.0;
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    if (before[i] && !after[i]) v += geometry(t, t.leaf(i)).extent().prod();
  return v;
}

/// A mesh saved before a refinement of the octants on the surface (RepairLoop::saved).
struct Saved {
  Result3d r;
  Orthtree<3> tree;
  Flags in;
  OctantComplexResult oc;
  TetMesh fe;
  bool topology_right = true;  ///< false: its Euler characteristic is wrong (not a valid mesh)
  bool smoothed = true;        ///< false: saved before the quality stage (a wrong topology)
};

// An island refinement above island_max_fraction is tried once: kept when no island is left
// (the thin part is resolved: tori at level 3, whose whole tube is two octants thick, and
// regressions/voxel-island-trial.off go to 0 islands), else the tree before it comes back
// (rotor's blades multiply their islands: L4 82 -> 1164). Fewer islands, or less of their
// volume, is not enough: finer islands have less volume though the part is no better
// resolved, and where islands remain the refined parts are sheets of interior octants one
// octant thick whose boundary octants fold (rotor L5, blades 1.2 level-6 octants thick:
// 1125 -> 1167 islands, volume 0.00497 -> 0.00064, then 25k raw inverted tets and ~2200
// problems per repair; without the buffer rule 1241 -> 419 islands, volume 0.0055 ->
// 0.00023, then 1570 problems; the run was refused by the work bound after 7.3 CPU
// minutes). Its tries count as island refinements for the repair budget.
struct IslandTrial {
  Orthtree<3> tree;  ///< before the refinement
  double island_volume = 0.0;
  std::size_t n_islands = 0;
};

// The tree before a refinement and its answers, from the refinement to the next
// classification, which asks only the leaves below its Partial ones (classify_refined). Not
// kept longer: a copy kept to the end raised sphere966 L6's peak RSS by 4.6 MB (the heap's
// peak the same).
struct Classified {
  Orthtree<3> tree;
  std::vector<Side> sides;
};

/// What the repair loop builds on one tree: its interior octants, boundary octants and mesh,
/// and what is wrong with them.
struct TreeMesh {
  bool last = false;  ///< no repair is left after this tree (Options3d::max_repairs)
  std::vector<Side> sides;
  Flags in;
  Flags before_islands;  ///< `in` before keep_largest_components
  OctantComplexResult oc;
  std::vector<Problem3> problems;
  TetMesh fe;
  // Set when the Escobar pass made this tree's mesh positive: the problems the old path would
  // have reported, in case the mesh turns out not to be conforming after all.
  std::optional<std::vector<Problem3>> before_escobar;
  std::vector<P3> at_fault_before_escobar;  // with opt.repair_at_cells: where those lie
  std::vector<P3> behind;  // lattice nodes behind what the untangling left inverted or folded
  std::vector<P3> at_fault;  // with opt.repair_at_cells: where the repair refines instead
  // Set when the untangling left folded interface triangles but no inverted tetrahedron and
  // opt.accept_valid_folds: the folds, refined around unless the smoothed mesh validates.
  std::optional<std::vector<Problem3>> folds_pending;
  bool topology_right = false;  // known to be right (refine_for_topology_before_quality)
  // The validator's report with the surface's checks, when the mesh passed it (handed on with
  // the mesh: Result3d::validation).
  std::optional<ValidationReport> report;
};

/// One try of the pipeline (mesh3d_once): the first tree, then one tree after another, each
/// refined or peeled around the problems of the one before, until one's mesh has none. Not
/// copied: its timer writes into its own r.
struct RepairLoop {
  SurfaceBoundary& s;
  const Options3d& opt;
  Effort& effort;
  const Progress3& progress;
  const Progress3 say = [this](const std::string& msg) {
    if (progress) progress(msg);
  };
  Result3d r;
  StageTimer clock{r.times};
  int max_level = 0;
  BalanceOptions balancing;
  Orthtree<3> tree;
  const SurfacePointFn surface_point = [this](const P3& p) {
    const ClosestPoint<3> cp = s.closest_point(p);
    return std::make_pair(P3(cp.point), cp.where);
  };
  const std::function<P3(const BoundaryLocation&)> surface_normal = [this](const BoundaryLocation& w) {
    return w.patch >= 0 ? s.surface().normal(w.patch) : P3(P3::Zero());
  };

  int attempt = 0;  // one per classification of a tree; the repair messages count from 1
  std::vector<P3> peel_points;
  int peel_rounds = 0;  // peels of this tree (reset by a refinement)
  std::size_t n_prev_problems = 0;
  int n_worse = 0;  // repairs that left more problems than the tree before (Options3d::worse_repairs)
  int topology_refinements = 0;
  std::optional<Saved> saved;  // the last mesh whose topology or islands a refinement tries to fix
  int island_refinements = 0;
  std::optional<IslandTrial> island_trial;
  bool island_trial_done = false;
  bool island_trial_reverted = false;  // the trial did not resolve the thin parts
  int trial_attempts = 0;  // attempts spent on a reverted trial
  std::optional<Classified> classified;
  bool first_of_run = false;  // this loop's first tree is its run's first (Effort::first_tree_built)
  bool tetrahedra_built = false;  // make_tetrahedra has run on a tree of this loop

  RepairLoop(SurfaceBoundary& surface, const Options3d& options, Effort& work, const Progress3& say_to)
      : s(surface), opt(options), effort(work), progress(say_to) {}
  RepairLoop(const RepairLoop&) = delete;
  RepairLoop& operator=(const RepairLoop&) = delete;

  /// The surface's level field from opt: global, feature and thickness levels.
  void surface_levels() {
    s.set_global_level(opt.level);
    s.set_max_level(opt.level + opt.extra_levels);
    s.set_thickness_level(opt.thickness_cells, opt.level + opt.thickness_extra_levels);
  }

  /// The surface's levels from opt, and the first tree: subdivided by the level field and 2:1
  /// balanced. Sets the work bound when the run has none yet.
  void first_tree() {
    const int thickness_max_level = opt.level + opt.thickness_extra_levels;
    max_level = opt.max_level >= 0 ? opt.max_level
                : opt.thickness_cells > 0
                    ? std::max(opt.level + opt.extra_levels + 2, thickness_max_level)
                    : opt.level + opt.extra_levels + 2;
    surface_levels();
    RefineOptions ro;
    ro.max_level = max_level;
    ro.max_leaves = opt.max_cells;
    ro.n_threads = opt.n_threads;

    say("octree: subdividing by the level field (global level " + std::to_string(opt.level) + ")");
    const ControlFn<3> control = [&](const Box<3>& b) { return s.control_level(b); };
    tree = subdivide_by_control(s.root_box(), control, ro);
    r.n_leaves_subdivided = tree.n_leaves();
    clock.lap("subdivide");
    say("octree: " + std::to_string(tree.n_leaves()) + " octants; 2:1 balance");
    // Balanced across faces, edges and corners: every face of an octant then has at most one
    // level of hanging nodes, which the face templates assume.
    balancing.n_threads = opt.n_threads;  // the same tree for every count
    tree = balance_2to1(tree, BalanceKind::Full, balancing);
    clock.lap("balance");
    first_of_run = !std::exchange(effort.first_tree_built, true);
    if (effort.limit == 0)
      effort.limit = std::max(static_cast<std::size_t>(opt.effort * static_cast<double>(tree.n_leaves())),
                              opt.min_effort_octants);
  }

  /// The tree refined where `flags` are set and 2:1 balanced; `sides` are the tree's answers.
  void refine_tree(const Flags& flags, const std::vector<Side>& sides) {
    Orthtree<3> finer = balance_2to1(refine(tree, flags), BalanceKind::Full, balancing);
    classified = Classified{std::move(tree), sides};
    tree = std::move(finer);
  }

  /// The valid coarser mesh in `saved` stands (with its volume warning) when the finer tree's
  /// cannot be built.
  Result3d restore_saved() {
    if (!saved->smoothed) {
      improve_quality(s, saved->oc.complex, saved->fe, opt, surface_point, surface_normal, saved->r, say);
      clock.lap("smoothing");
    }
    std::vector<StageTime3> times = std::move(r.times);
    r = std::move(saved->r);
    r.times = std::move(times);
    if (opt.hex_dominant) r.hex = make_hex_dominant(saved->tree, saved->oc.complex, saved->fe, opt.hex);
    r.stats = saved->oc.stats;
    r.fe = std::move(saved->fe);
    r.interior = std::move(saved->in);
    r.tree = std::move(saved->tree);
    return std::move(r);
  }

  /// The tree's interior octants: classified, less those the buffer rules, the peels, the pinch
  /// rule, the opposing free faces (opt.drop_opposing) and the islands drop.
  void classify_octants(TreeMesh& tm) {
    say("interior octants: classifying " + std::to_string(tree.n_leaves()) + " octants");
    tm.sides =
        classified ? classify_refined(tree, classified->tree, classified->sides, s, opt.n_threads) : classify(tree, s, opt.n_threads);
    classified.reset();
    tm.in = interior_flags(tm.sides);
    r.n_buffer_dropped = apply_buffer_rules(tree, tm.in, s, opt);
    r.n_peeled = peel(tree, tm.in, peel_points);
    r.n_pinches_dropped = remove_pinches(tree, tm.in, opt.n_threads);
    r.n_opposing_dropped = 0;
    const auto depth_at = [this](const P3& p) { return s.closest_point(p).distance; };
    for (int round = 0; opt.drop_opposing && round < 4; ++round) {
      const std::size_t k = remove_opposing(tree, tm.in, depth_at);
      if (k == 0) break;
      r.n_opposing_dropped += k;
      r.n_pinches_dropped += remove_pinches(tree, tm.in, opt.n_threads);
    }
    tm.before_islands = tm.in;
    r.n_islands_dropped = keep_largest_components(tree, tm.in, s.n_components());
  }

  /// After the island trial's refinement (IslandTrial): keeps it when no island is left, else
  /// brings the tree before it back and returns true (build on that one).
  bool revert_island_trial(const TreeMesh& tm) {
    if (!island_trial) return false;
    const double volume_after = island_volume(tree, tm.before_islands, tm.in);
    const bool kept = r.n_islands_dropped == 0;
    say("interior octants: " + std::to_string(r.n_islands_dropped) + " in islands after the refinement above " +
        "the share limit (" + std::to_string(island_trial->n_islands) + " before; their volume " +
        std::to_string(volume_after) + ", " + std::to_string(island_trial->island_volume) + " before); " +
        (kept ? "keeping it" : "going back to the tree before it"));
    if (!kept) {
      tree = std::move(island_trial->tree);
      island_trial.reset();
      island_trial_reverted = true;
      --island_refinements;  // the trial and this attempt count as trial_attempts instead
      trial_attempts += 2;
      return true;
    }
    island_trial.reset();
    return false;
  }

  /// Where islands were dropped, up to opt.island_refinements times: refines around them (and
  /// the thin surface, opt.thin_cells) and returns true.
  bool refine_around_islands(const TreeMesh& tm) {
    if (!(r.n_islands_dropped > 0 && island_refinements < opt.island_refinements)) return false;
    // A part thinner than the octants falls apart: refine around the pieces it left before
    // building anything on this tree (refining every octant on the surface instead folds).
    std::vector<P3> places;
    for (std::size_t i = 0; i < tree.n_leaves(); ++i)
      if (tm.before_islands[i] && !tm.in[i]) places.push_back(geometry(tree, tree.leaf(i)).center());
    Flags flags;
    bool marked = mark_around<3>(tree, places, opt.island_cells, max_level, flags);
    if (opt.thin_cells > 0) {
      // The rest of such parts: the octants on surface thinner than thin_cells of their size,
      // whose handles would be lost without an island to show it.
      const std::vector<double>& thickness = s.centroid_thicknesses();
      for (std::size_t i = 0; i < tree.n_leaves(); ++i) {
        if (tm.sides[i] != Side::Partial || tree.leaf(i).level >= max_level || flags[i]) continue;
        const Box<3> b = geometry(tree, tree.leaf(i));
        const double limit = opt.thin_cells * b.extent()[0];
        bool thin = false;
        s.tree().for_each_in_box(b, [&](std::int32_t t) {
          if (thin || !(thickness[t] < limit)) return;
          const auto& q = s.tree().points(t);
          thin = box_triangle_overlap(b, q[0], q[1], q[2]);
        });
        if (thin) flags[i] = 1, marked = true;
      }
    }
    const std::size_t n_marked = static_cast<std::size_t>(std::count(flags.begin(), flags.end(), 1));
    // Where most of the surface is thin (rotor's blades at level 4) the level is too coarse
    // for the shape, not for a few handles: refining all of it multiplies the islands and the
    // octants (measured: rotor 12608 -> 324647 octants, islands 82 -> 1164).
    const bool over_share = n_marked > opt.island_max_fraction * tree.n_leaves();
    if (marked && over_share && !island_trial_done) {
      island_trial_done = true;
      island_trial = IslandTrial{tree, island_volume(tree, tm.before_islands, tm.in), r.n_islands_dropped};
    }
    if (marked && (!over_share || island_trial)) {
      ++island_refinements;
      say("interior octants: " + std::to_string(r.n_islands_dropped) + " in islands; refining " +
          std::to_string(n_marked) + " octants around them and on thin surface");
      refine_tree(flags, tm.sides);
      clock.lap("island refinement");
      return true;
    }
    return false;
  }

  /// The pinch rule once more after islands were dropped, and the classification's counts.
  void end_classification(TreeMesh& tm) {
    if (r.n_islands_dropped > 0) r.n_pinches_dropped += remove_pinches(tree, tm.in, opt.n_threads);
    say("interior octants: " + std::to_string(r.n_buffer_dropped) + " dropped by the buffer rule, " +
        std::to_string(r.n_peeled) + " peeled, " + std::to_string(r.n_pinches_dropped) + " for pinches, " +
        (r.n_opposing_dropped > 0 ? std::to_string(r.n_opposing_dropped) + " for opposing free faces, " : std::string()) +
        std::to_string(r.n_islands_dropped) + " in islands");
    clock.lap(attempt == 0 ? "classify" : "classify (repair " + std::to_string(attempt) + ")");
  }

  /// Counts the tree in the work bound (Options3d::effort). Past it: true when a saved mesh
  /// stands (restore_saved), else LimitError.
  bool over_work_bound() {
    // The work bound counts the trees the construction below is built on: it, the untangling
    // and the smoothing cost about the same per octant on every try (the classification and
    // the island refinements above are cheaper).
    effort.used += tree.n_leaves();
    if (effort.used > effort.limit) {
      const std::string why = "building on " + std::to_string(tree.n_leaves()) + " more octants would bring this run to " +
                              std::to_string(effort.used) + ", over its work bound of " + std::to_string(effort.limit) +
                              " (" +
                              (effort.limit_origin.empty()
                                   ? std::to_string(static_cast<int>(opt.effort)) + "x the first tree's octants, --effort"
                                   : effort.limit_origin) +
                              ")";
      if (saved) {
        say("repair " + std::to_string(attempt + 1) + ": " + why + "; keeping the mesh before the refinement");
        return true;
      }
      throw LimitError("the boundary octants could not be built within the work bound: " + why + ", after " +
                       std::to_string(r.n_repairs) + " repair(s); try another --level, or a larger --effort");
    }
    return false;
  }

  /// The boundary octants on the tree's interior octants; their problems are the tree's first.
  void build_boundary_octants(TreeMesh& tm) {
    say("boundary octants: projecting the free faces onto the surface");
    BoundaryOctantOptions bo;
    bo.snap_features = opt.snap_features;
    bo.graze = opt.graze;
    bo.graze_region = opt.graze_region;
    bo.graze_length = opt.graze_length;
    bo.backward_along = opt.backward_along;
    bo.min_outward = opt.min_outward;
    bo.min_facing = opt.min_facing;
    bo.outward_all_faces = opt.outward_all_faces;
    bo.rays = opt.projection_rays;
    bo.unfold_backward = opt.unfold_backward;
    bo.in_plane_cosine = opt.in_plane_cosine;
    bo.n_threads = opt.n_threads;
    tm.oc = build_octant_complex(tree, tm.in, s, bo);
    clock.lap("boundary octants");
    tm.problems = tm.oc.problems;
  }

  /// Parts thinner than the octants fall apart (islands dropped) or lose a handle (the
  /// solid's Euler characteristic is not half the surface's): refine the octants the surface
  /// crosses once more and rebuild, rather than keep a mesh that misses them. `smoothed`: the
  /// quality stage has run (islands are looked at only then: that mesh may stand, the saved
  /// one); `euler`: the mesh's Euler characteristic, when looked at. True when the tree was
  /// refined.
  bool refine_surface_octants(TreeMesh& tm, bool smoothed, std::optional<long> euler) {
    const bool empty = tm.fe.mesh.solid.empty();
    const bool topology_wrong =
        empty || (euler && s.euler_characteristic() % 2 == 0 && *euler != s.euler_characteristic() / 2);
    // Not for islands alone where the island trial showed that one level more does not
    // resolve them: refining every octant on the surface is that refinement and more (rotor
    // L5: 14125 octants refined, then 678 -> 338 -> 736 -> 439 problems over the repairs, the
    // valid mesh before it standing in the end, minutes of CPU later).
    const bool islands_unresolvable = island_trial_reverted && !topology_wrong;
    if (!((topology_wrong || (smoothed && r.n_islands_dropped > 0)) && !islands_unresolvable)) return false;
    Flags flags(tree.n_leaves(), 0);
    std::size_t n_marked = 0;
    const auto mark_if_refinable = [&](std::size_t i) {
      if (!flags[i] && tm.sides[i] == Side::Partial && tree.leaf(i).level < max_level) flags[i] = 1, ++n_marked;
    };
    // With opt.topology_gap, a wrong Euler characteristic refines only the octants on the
    // surface within reach of the surface the BE mesh misses.
    std::size_t n_missed = 0;
    if (topology_wrong && !empty && opt.topology_gap > 0) {
      double finest = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < tree.n_leaves(); ++i)
        if (tm.sides[i] == Side::Partial) finest = std::min(finest, geometry(tree, tree.leaf(i)).extent()[0]);
      const auto side_at = [&](const P3& p) {
        const std::size_t i = locate(tree, p);
        return i == no_leaf ? finest : geometry(tree, tree.leaf(i)).extent()[0];
      };
      const std::vector<MissedPoint> missed =
          missed_surface(tm.fe.mesh, s, 0.5 * finest, [&](const P3& p) { return opt.topology_gap * side_at(p); });
      n_missed = missed.size();
      for (const MissedPoint& m : missed) {
        Box<3> reach{m.p, m.p};
        reach.lo.array() -= m.distance;
        reach.hi.array() += m.distance;
        for (const std::size_t i : leaves_in_box(tree, reach)) mark_if_refinable(i);
      }
    }
    if (n_marked == 0)
      for (std::size_t i = 0; i < tree.n_leaves(); ++i) mark_if_refinable(i);
    if (n_marked == 0) return false;
    ++topology_refinements;
    ++r.n_repairs;
    say("repair " + std::to_string(attempt + 1) + ": refining the " + std::to_string(n_marked) +
        " octants on the surface" +
        (n_missed > 0 ? " within reach of " + std::to_string(n_missed) + " point(s) of it the BE mesh misses" : std::string()) +
        " (" +
        (empty            ? std::string("no interior octant: the solid is thinner than the octants everywhere")
         : topology_wrong ? "Euler characteristic " + std::to_string(*euler) + ", expected " +
                                std::to_string(s.euler_characteristic() / 2)
                          : std::to_string(r.n_islands_dropped) + " octants in islands") +
        ")");
    saved = Saved{r, tree, tm.in, tm.oc, std::move(tm.fe), !topology_wrong, smoothed};
    n_prev_problems = std::numeric_limits<std::size_t>::max();  // a fresh start for the repairs
    refine_tree(flags, tm.sides);
    clock.lap("repair refinement");
    return true;
  }

  /// The tetrahedra from templates, untangled: rounds of the untangling passes and surface node
  /// moves, undoing the feature snaps at what stays inverted or folded, until nothing is, or
  /// the last resort leaves problems (untangle_last_resort).
  void make_tetrahedra(TreeMesh& tm) {
    say("finite elements: templates");
    // Feature snaps that invert an element are undone, then the templates are redone.
    // The rounds move the complex's nodes only: the interior octants' part is built once.
    InteriorTets interior_tets;
    for (int round = 0;; ++round) {
      tm.fe = tetrahedralize(tree, tm.oc.complex, surface_point, opt.n_threads, &interior_tets, &tm.fe);
      const std::vector<Box<3>> bounds =
          opt.untangle_reach > 0 ? move_bounds(tree, tm.oc.complex, tm.fe, opt.untangle_reach) : std::vector<Box<3>>{};
      // Untangle by moving nodes (interior ones freely, surface ones on the surface,
      // corners not at all) before giving up snaps or refining.
      const TetOptimizeStats ts =
          untangle_pass(tm.fe, tm.oc.complex, opt.untangle_sweeps, false, surface_point, surface_normal, opt.n_threads, bounds);
      r.n_untangle_moves += ts.moves;
      say(untangle_summary("untangling", ts));
      if (round == 0 && !std::exchange(tetrahedra_built, true) && opt.first_round_inverted_share > 0 &&
          static_cast<double>(ts.inverted_after) > opt.first_round_inverted_share * static_cast<double>(ts.inverted_before))
        throw GeometryError("the first round of untangling left " + std::to_string(ts.inverted_after) + " of " +
                            std::to_string(ts.inverted_before) + " tetrahedra inverted");
      const std::vector<std::size_t> bad = inverted_elements(tm.fe.mesh, opt.n_threads);
      const std::vector<std::size_t> folded = folded_faces(tm.fe.mesh, tm.fe.where, s, opt.n_threads);
      std::set<std::int32_t> revert;
      const auto revert_snapped = [&](const Elements& elems, std::size_t e) {
        const VertexId* v = elems.nodes(ElemId{static_cast<std::int32_t>(e)});
        for (int k = 0; k < elems.n_nodes_of(ElemId{static_cast<std::int32_t>(e)}); ++k) {
          const std::int32_t id = v[k].v;
          if (id < static_cast<std::int32_t>(tm.oc.complex.snapped.size()) && tm.oc.complex.snapped[id]) revert.insert(id);
        }
      };
      for (std::size_t e : bad) revert_snapped(tm.fe.mesh.solid, e);
      for (std::size_t f : folded) revert_snapped(tm.fe.mesh.interface, f);
      if (bad.empty() && folded.empty()) break;
      if (revert.empty()) {
        const int last_round = opt.untangle_rounds + 4;  // the round that no longer moves surface nodes
        std::vector<UntangleUndo> undo;
        const std::size_t moved =
            round < last_round
                ? untangle(tree, tm.in, s, opt.graze, opt.graze_region, opt.graze_length, bad, tm.oc.complex, tm.fe, &undo)
                : 0;
        r.n_untangled += moved;
        if (moved > 0 && opt.skip_repeated_rounds && complex_unchanged(undo, tm.oc.complex)) {
          // Every node went back to the complex point it had: the next round's tetrahedra and
          // untangling are this round's, bit for bit, and so are its moves, up to the last
          // round. Skip to that round's end (its mesh is this one before the moves; the counts
          // as if the rounds had run). Measured: the same mesh.msh and report counts.
          for (auto u = undo.rbegin(); u != undo.rend(); ++u)
            tm.fe.mesh.points[static_cast<std::size_t>(u->node)] = u->mesh_point;
          const std::size_t repeats = static_cast<std::size_t>(last_round - round - 1);
          r.n_untangled += repeats * moved;
          r.n_untangle_moves += (repeats + 1) * ts.moves;
          say("untangling: the " + std::to_string(repeats + 1) +
              " round(s) after this one would repeat it (every moved node back where it was): skipped");
          untangle_last_resort(tm, bad, folded, bounds);
          break;
        }
        if (moved == 0) {
          untangle_last_resort(tm, bad, folded, bounds);
          break;
        }
        continue;
      }
      for (std::int32_t id : revert) {
        tm.oc.complex.points[id] = tm.oc.complex.unsnapped[id];
        tm.oc.complex.where[id] = s.closest_point(tm.oc.complex.unsnapped[id]).where;
        tm.oc.complex.snapped[id] = 0;
        ++r.n_snaps_reverted;
      }
    }
    clock.lap("templates");
  }

  /// Where no surface node move helps any more (`bad` inverted, `folded`): the Escobar pass,
  /// then what is left either waits for the validator (folds only, opt.accept_valid_folds) or
  /// becomes the tree's problems, with the places behind them.
  void untangle_last_resort(TreeMesh& tm, const std::vector<std::size_t>& bad, const std::vector<std::size_t>& folded,
                            const std::vector<Box<3>>& bounds) {
    // Last resort on this tree: where no node move raises the worst tetrahedron, the
    // smooth Escobar objective still descends (tet_optimize). Only here, so that the
    // meshes the max-min untangling already makes valid stay bit for bit the same.
    std::vector<std::size_t> bad2 = bad, folded2 = folded;
    if (opt.escobar_sweeps > 0) {
      std::vector<Problem3> old_problems;
      add_problems(tm.fe.mesh, bad, folded, "", old_problems);
      if (opt.repair_at_cells)
        tm.at_fault_before_escobar =
            fault_places(tree, tm.oc.complex, tm.fe, bad, nodes_behind(tree, tm.oc.complex, tm.fe.mesh, bad, folded));
      const TetOptimizeStats ts =
          untangle_pass(tm.fe, tm.oc.complex, opt.escobar_sweeps, true, surface_point, surface_normal, opt.n_threads, bounds);
      r.n_untangle_moves += ts.moves;
      say(untangle_summary("untangling (Escobar objective)", ts));
      bad2 = inverted_elements(tm.fe.mesh, opt.n_threads);
      folded2 = folded_faces(tm.fe.mesh, tm.fe.where, s, opt.n_threads);
      if (bad2.empty() && folded2.empty()) tm.before_escobar = std::move(old_problems);
    }
    if (bad2.empty() && opt.accept_valid_folds) {
      // Only folds left, every tetrahedron positive: the validator decides after the
      // smoothing (validate_folds).
      std::vector<Problem3> fold_problems;
      add_problems(tm.fe.mesh, bad2, folded2, "", fold_problems);
      tm.folds_pending = std::move(fold_problems);
      return;
    }
    add_problems(tm.fe.mesh, bad2, folded2, "", tm.problems);
    if (!(bad2.empty() && folded2.empty())) tm.behind = nodes_behind(tree, tm.oc.complex, tm.fe.mesh, bad2, folded2);
    if (opt.repair_at_cells) tm.at_fault = fault_places(tree, tm.oc.complex, tm.fe, bad2, tm.behind);
  }

  /// May the octants on the surface still be refined for the topology (refine_surface_octants)?
  bool surface_refinement_left(const TreeMesh& tm) const {
    return topology_refinements < opt.topology_refinements &&
           (!opt.surface_refinements_empty_only || tm.fe.mesh.solid.empty());
  }

  /// True when the mesh's Euler characteristic is wrong and the octants on the surface were
  /// refined for it before the quality stage (refine_surface_octants).
  bool refine_for_topology_before_quality(TreeMesh& tm) {
    // A wrong Euler characteristic sends the tree to that refinement whatever the quality stage
    // does, and the stage keeps it (no move inverts a tetrahedron; edge removal and contraction
    // keep the links): so it is looked at before the stage, which then runs on the finer tree
    // only. Not where the validator decides on this tree's folds after the stage; a mesh the
    // Escobar pass made positive goes to that refinement only if it validates (else its problems
    // are refined around, below). Measured (CLI, one thread, user s; the same mesh.msh on all 12
    // level-4 runs and the 6 level-5 tetrahedral ones): elephant L4 38.1 -> 31.7, anchor L4 7.8
    // -> 6.9.
    if (!(tm.problems.empty() && !tm.folds_pending && surface_refinement_left(tm) && !tm.last)) return false;
    // The validator's checks without the surface's (on all threads: the same report).
    const auto validation = [&](const Mesh<3>& m) {
      ValidateOptions<3> vo;
      vo.n_threads = opt.n_threads;
      return validate(m, vo);
    };
    const long euler = euler_characteristic<3>(tm.fe.mesh, opt.n_threads);
    // A tree without an interior octant meshes nothing, whose Euler characteristic 0 is a
    // torus's: wrong too (a thin torus at 1.75 level-3 octants, session 43, stood empty).
    tm.topology_right = !tm.fe.mesh.solid.empty() &&
                        (s.euler_characteristic() % 2 != 0 || euler == s.euler_characteristic() / 2);
    return !tm.topology_right && (!tm.before_escobar || validation(tm.fe.mesh).valid) &&
           refine_surface_octants(tm, false, euler);
  }

  /// The quality stage on the tree's positive mesh, then the checks that may still find
  /// problems in it: inverted tetrahedra and folds after the stage, the validator where folds
  /// are pending or the Escobar pass made the mesh positive, else the surface's contacts.
  void improve_and_check(TreeMesh& tm) {
    // Set when the whole mesh passed the validator below (folds, or the Escobar pass): its
    // geometric checks include surface_contacts' on the whole mesh (hanging and duplicate nodes,
    // facets used twice; the duplicate tolerance is relative to the box of the nodes, larger
    // for the whole mesh than for the tetrahedra at the surface), so those are not run again
    // (elephant L4: the kept tree comes from the Escobar pass).
    bool validated = false;
    improve_quality(s, tm.oc.complex, tm.fe, opt, surface_point, surface_normal, r, say);
    clock.lap("smoothing");
    add_problems(tm.fe.mesh, inverted_elements(tm.fe.mesh, opt.n_threads),
                 tm.folds_pending ? std::vector<std::size_t>{} : folded_faces(tm.fe.mesh, tm.fe.where, s, opt.n_threads),
                 " after smoothing", tm.problems);
    if (tm.problems.empty() && tm.folds_pending) validated = validate_folds(tm);
    else if (tm.problems.empty() && tm.before_escobar) validated = validate_after_escobar(tm);
    if (validated) clock.lap("validation");
    if (tm.problems.empty() && !validated) check_surface_contacts(tm);
  }

  /// With folds pending: true when the smoothed mesh is valid (its report kept), else the folds
  /// are the tree's problems.
  bool validate_folds(TreeMesh& tm) {
    // Folded interface triangles where the surface's normals at their nodes disagree (the
    // two sheets of a lip thinner than the octants): the fold test has no reference there.
    // The mesh stands if it is valid (conforming, interface = boundary faces on the surface).
    const ValidationReport v = validate(tm.fe.mesh, surface_validation(s, opt.n_threads));
    say("folded interface triangles: " + std::to_string(tm.folds_pending->size()) + " after untangling; the mesh is " +
        (v.valid ? "valid" : "not valid (" + v.summary() + ")"));
    if (v.valid) tm.report = v;
    if (!v.valid) tm.problems = std::move(*tm.folds_pending);
    return v.valid;
  }

  /// After the Escobar pass made the mesh positive: true when it conforms (its report kept),
  /// else the problems before that pass (or where it does not conform) are the tree's.
  bool validate_after_escobar(TreeMesh& tm) {
    // Positive tetrahedra can still overlap where the surface mesh covers a strip twice
    // (measured: regressions/torus-12x8-feature-snap-inverted.off, hanging nodes): then do
    // what the max-min untangling alone would have done, refine around its problems. Not
    // after validate_folds, whose checks include these. With the surface's checks, so
    // that the report can go on with the mesh; whether it conforms is the validation without
    // them (ValidationReport::conforms).
    const ValidationReport v = validate(tm.fe.mesh, surface_validation(s, opt.n_threads));
    const bool conforms = v.conforms();
    if (conforms) tm.report = v;
    if (!conforms) {
      say("untangling (Escobar objective): the mesh does not conform; refining instead");
      tm.problems = std::move(*tm.before_escobar);
      tm.at_fault = std::move(tm.at_fault_before_escobar);
      if (opt.repair_at_cells) {
        // The problems are where it does not conform (counted as such: the inverted
        // tetrahedra before the Escobar pass are not this tree's count), refined around
        // with the faults behind those tetrahedra.
        std::vector<Problem3> sites;
        for (const auto& site : v.sites)
          if (site.node >= 0 && std::string_view(site.kind) != off_boundary_kind)
            sites.push_back({tm.fe.mesh.points[static_cast<std::size_t>(site.node)], site.kind});
        if (!sites.empty()) {
          for (const Problem3& p : sites) tm.at_fault.push_back(p.where);
          tm.problems = std::move(sites);
        }
      }
    }
    return conforms;
  }

  /// Where the surface mesh touches itself, the tree's problems.
  void check_surface_contacts(TreeMesh& tm) {
    // The checks above see inverted tetrahedra and folds, not a surface mesh that touches
    // itself: two sheets meeting on a concave feature line can leave a node of one on an
    // edge of the other (measured: regressions/voxel-hanging-node-concave-edge.off, level
    // 3, one hanging node after three repairs, accepted and then refused by the CLI's
    // validation). The validator's geometric checks on the tetrahedra at the surface find
    // such contacts; refine around them.
    // A tetrahedral mesh is validated whole here first, and the report goes on with it (the
    // run's ranking and the CLI take it instead of validating again): the whole mesh's
    // hanging nodes, duplicates and facets used twice include the surface tetrahedra's (the
    // same checks on a superset of nodes, edges and facets, the duplicate tolerance relative to
    // a larger box), so where it finds none there is no contact, and surface_contacts, which
    // then repeated a part of the validation (sphere966 at 995,232 tetrahedra: 0.14 s before
    // the validation's 0.61), runs only where it finds some. Not for hex-dominant meshes, whose
    // elements change after this (make_hex_dominant) and are validated then.
    if (!opt.hex_dominant) {
      ValidationReport v = validate(tm.fe.mesh, surface_validation(s, opt.n_threads));
      clock.lap("validation");
      if (v.hanging_nodes == 0 && v.duplicate_nodes == 0 && v.nonconforming_facets == 0) {
        tm.report = std::move(v);
        return;
      }
    }
    const std::vector<Problem3> contacts = surface_contacts(tm.fe.mesh, opt.n_threads);
    clock.lap("surface contacts");
    if (!contacts.empty()) {
      say("the surface mesh touches itself at " + std::to_string(contacts.size()) +
          " place(s); refining around them instead");
      tm.problems = contacts;
    }
  }

  /// The try's result: the tree's mesh without problems (hex-dominant with opt.hex_dominant).
  Result3d finish(TreeMesh& tm) {
    if (opt.hex_dominant) {
      say("finite elements: hexahedra where the cells conform");
      r.hex = make_hex_dominant(tree, tm.oc.complex, tm.fe, opt.hex);
      clock.lap("hex-dominant");
    }
    r.stats = tm.oc.stats;
    if (tm.report && !opt.hex_dominant) {
      r.validation = std::move(tm.report);
      r.validation_hash = content_hash(tm.fe.mesh);
    }
    r.fe = std::move(tm.fe);
    r.interior = std::move(tm.in);
    r.tree = std::move(tree);
    return std::move(r);
  }

  /// The repairs that drop interior octants instead of refining: at the problems that ask for it
  /// (opt.peel), else at the lattice nodes behind the faults (opt.peel_rounds). True when one
  /// was made.
  bool peel_around_problems(const TreeMesh& tm) {
    const std::vector<Problem3>& problems = tm.problems;
    if (opt.peel && !tm.last && std::any_of(problems.begin(), problems.end(), [](const Problem3& p) { return p.peel; })) {
      // Peel first, alone: refining would only move the same blind spot.
      for (const Problem3& p : problems)
        if (p.peel) peel_points.push_back(p.where);
      ++r.n_repairs;
      r.repaired.insert(r.repaired.end(), problems.begin(), problems.end());
      say("repair " + std::to_string(attempt + 1) + ": dropping the interior octants at " +
          std::to_string(problems.size()) + " place(s): " + describe(problems));
      return true;
    }
    if (!tm.behind.empty() && peel_rounds < opt.peel_rounds && !tm.last) {
      // Thicker boundary octants where the thin ones fold: drop the interior octants at the
      // lattice nodes behind them, then rebuild (refining moves such folds, measured).
      peel_points.insert(peel_points.end(), tm.behind.begin(), tm.behind.end());
      ++peel_rounds;
      n_prev_problems = problems.size();
      ++r.n_repairs;
      r.repaired.insert(r.repaired.end(), problems.begin(), problems.end());
      say("repair " + std::to_string(attempt + 1) + ": dropping the interior octants at " +
          std::to_string(tm.behind.size()) + " node(s) behind " + std::to_string(problems.size()) +
          " problem(s): " + describe(problems));
      return true;
    }
    return false;
  }

  /// Refines around the problems (or with opt.repair_at_cells the faults behind them) and
  /// returns true. When the finer tree cannot be built (the last repair, one that made things
  /// worse, the maximum level): false when the saved mesh stands (restore_saved), else
  /// GeometryError.
  bool refine_around_problems(const TreeMesh& tm) {
    const std::vector<Problem3>& problems = tm.problems;
    // Refining around inverted elements can add more than it removes (measured on fandisk,
    // rotor, spool, anchor, elephant): stop as soon as a repair makes things worse, after
    // opt.worse_repairs such repairs (the last try's allowance: its count is noisy).
    bool worse = attempt > island_refinements + trial_attempts && problems.size() > n_prev_problems;
    if (worse && n_worse < opt.worse_repairs && !tm.last) {
      ++n_worse;
      worse = false;
      say("repair " + std::to_string(attempt + 1) + ": " + std::to_string(problems.size()) + " problem(s), more than the " +
          std::to_string(n_prev_problems) + " before the last repair; one more (" + std::to_string(n_worse) + " of " +
          std::to_string(opt.worse_repairs) + " allowed)");
    }
    n_prev_problems = problems.size();
    Flags flags;
    // The problems' places, or with opt.repair_at_cells the faults behind them.
    std::vector<P3> places = tm.at_fault;
    if (places.empty())
      for (const Problem3& pr : problems) places.push_back(pr.where);
    const bool stuck = tm.last || worse || !mark_around<3>(tree, places, 1.5, max_level, flags);
    if (stuck && saved && saved->topology_right) {
      // The finer tree could not be built: the valid coarser mesh stands (with its volume
      // warning), rather than no mesh. Not one with the wrong Euler characteristic: the run
      // is refused instead, so that the next try (without feature snapping, ...) runs
      // (measured: regressions/torus-seed12-case195-euler.off, a 24x14 torus at level
      // 3, returned its first mesh with Euler characteristic 1 instead of 0).
      say("repair " + std::to_string(attempt + 1) + ": the refined tree has " + std::to_string(problems.size()) +
          " problem(s) (" + describe(problems) + "); keeping the mesh before the refinement");
      return false;
    }
    if (stuck)
      throw GeometryError("the boundary octants cannot be built (" + std::to_string(problems.size()) +
                          " problem(s) after " + std::to_string(r.n_repairs) + " repair(s)" +
                          (worse ? ", the last one made it worse" : ", maximum level " + std::to_string(max_level)) +
                          "): " + describe(problems));
    ++r.n_repairs;
    r.repaired.insert(r.repaired.end(), problems.begin(), problems.end());
    say("repair " + std::to_string(attempt + 1) + ": refining around " + std::to_string(problems.size()) +
        " place(s)" + (tm.at_fault.empty() ? std::string() : " (at " + std::to_string(tm.at_fault.size()) + " cells and nodes behind them)") +
        ": " + describe(problems));
    refine_tree(flags, tm.sides);
    peel_rounds = 0;
    clock.lap("repair refinement");
    return true;
  }

  /// Options3d::thickness_probe, once, after the run's first tree left problems: the thickness
  /// try's first tree, with no repair; its mesh when it has no problem and validates. `empty`:
  /// the first tree has no interior octant at all (the solid is thinner than the octants
  /// everywhere): the thin parts' try instead (thin_parts_try_options, its repairs included),
  /// which is not run again after the run's mesh (Effort::thin_early_refused) when refused. Measured
  /// (a plate 2 x 2 x 0.05 with a hole, level 4, CLI, two threads): every try refined the
  /// whole surface level by level, islands and folds, 55.7% of the volume lost after 19.6 s;
  /// the thin retry's try alone: 612,398 tets, 28.40 deg, 1.71%, 2.8 s. The surface gets this
  /// try's levels back either way.
  std::optional<Result3d> thickness_probe(bool empty) {
    if (!std::exchange(first_of_run, false) || !opt.thickness_probe || opt.thickness_cells > 0 ||
        !thickness_try_applies(s, opt) || (empty && !(opt.thin_retry_cells > 0)))
      return std::nullopt;
    Options3d thick;
    if (empty) {
      thick = thin_parts_try_options(s, opt, tree.n_leaves());
      say("no interior octant and the solid is thin: the thin parts' try with " + octants_across(thick.thickness_cells) +
          " them, without the buffer rule");
    } else {
      thick = thickness_try_options(opt);
      thick.max_repairs = 0;
      thick.first_round_inverted_share = 0.02;
      say("the first tree has problems and the solid has thin parts: the first tree with " +
          octants_across(thick.thickness_cells) + " them, without the buffer rule and without a repair");
    }
    const std::string what = empty ? "the thin parts' try" : "the first tree with the thickness level";
    std::string& refused = empty ? effort.thin_early_refused : effort.thickness_probe_refused;
    std::optional<Result3d> stands;
    Effort own;
    try {
      RepairLoop probe(s, thick, own, progress);
      Result3d t = probe.run();
      if (const ValidationReport& v = validation_of(t, s, opt.n_threads); v.valid) {
        t.thickness_early = true;
        std::vector<StageTime3> times = r.times;
        times.insert(times.end(), t.times.begin(), t.times.end());
        t.times = std::move(times);
        stands = std::move(t);
        say("thin parts: " + what + " stands");
      } else {
        refused = "not valid: " + v.summary();
        say("thin parts: " + what + " is not valid (" + v.summary() + "); going on");
      }
    } catch (const GeometryError& e) {
      refused = e.what();
      say("thin parts: " + what + " has problems (" + e.what() + "); going on");
    } catch (const LimitError& e) {
      refused = e.what();
      say("thin parts: " + what + " is over its bounds (" + e.what() + "); going on");
    }
    effort.used += own.used;
    surface_levels();
    return stands;
  }

  /// The loop: a tree after another until one's mesh has no problem (or the try stops).
  Result3d run() {
    first_tree();
    for (attempt = 0;; ++attempt) {
      TreeMesh tm;
      tm.last = attempt - island_refinements - trial_attempts >= opt.max_repairs;
      classify_octants(tm);
      if (revert_island_trial(tm) || refine_around_islands(tm)) continue;
      end_classification(tm);
      if (over_work_bound()) return restore_saved();
      build_boundary_octants(tm);
      if (tm.problems.empty()) make_tetrahedra(tm);
      if (tm.problems.empty() && tm.fe.mesh.solid.empty())
        if (std::optional<Result3d> thin = thickness_probe(true)) return std::move(*thin);
      if (refine_for_topology_before_quality(tm)) {
        first_of_run = false;  // the probe looks at the run's first tree only
        continue;
      }
      if (tm.problems.empty()) improve_and_check(tm);
      if (tm.problems.empty() && surface_refinement_left(tm) && !tm.last) {
        std::optional<long> euler;
        if (!tm.topology_right) euler = euler_characteristic<3>(tm.fe.mesh, opt.n_threads);
        if (refine_surface_octants(tm, true, euler)) {
          first_of_run = false;
          continue;
        }
      }
      if (tm.problems.empty()) return finish(tm);
      if (std::optional<Result3d> thick = thickness_probe(false)) return std::move(*thick);
      if (peel_around_problems(tm)) continue;
      if (!refine_around_problems(tm)) return restore_saved();
    }
  }
};

}  // namespace

Result3d mesh3d_once(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  RepairLoop loop(s, opt, effort, progress);
  Result3d r = loop.run();
  // No try stands on an empty mesh (the validator refuses it too): the fallbacks, the lattice
  // draws and the level raise take it as the refusal it is.
  if (r.fe.mesh.solid.empty()) {
    std::ostringstream why;
    why << "no interior octant: every part of the solid is thinner than the octants ("
        << s.octant_side(opt.level) << " across; a finer --level or --size meshes it)";
    throw GeometryError(why.str());
  }
  return r;
}

}  // namespace febemesh::dim3
