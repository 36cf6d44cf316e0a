#include "dim2/pipeline2d.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/local_repair.hpp"
#include "core/parallel_ranges.hpp"
#include "core/partitioned_sweep.hpp"
#include "core/quality.hpp"
#include "core/smooth.hpp"
#include "dim2/heap_policy.hpp"
#include "dim2/improve2d.hpp"
#include "dim2/loop_geometry.hpp"
#include "dim2/optimise_angles.hpp"

namespace febemesh::dim2 {
namespace {

std::string describe(const std::vector<Problem>& problems) {
  std::ostringstream os;
  os.precision(6);
  const std::size_t shown = std::min<std::size_t>(problems.size(), 3);
  for (std::size_t k = 0; k < shown; ++k)
    os << (k ? "; " : "") << problems[k].what << " near (" << problems[k].where[0] << ", " << problems[k].where[1]
       << ")";
  if (problems.size() > shown) os << "; and " << problems.size() - shown << " more";
  return os.str();
}

/// Elements that came out inverted (or flat), as problems at their centroids, in element order;
/// checked in fixed chunks on n_threads threads (serial, it was 0.1 s of the flange's 2.5 s at
/// 5.4 M triangles on two threads).
std::vector<Problem> inverted_elements(const Mesh<2>& m, int n_threads) {
  const std::size_t chunk = chunk_size(m.solid.size(), n_threads, 1 << 14);
  std::vector<std::vector<Problem>> found((m.solid.size() + chunk - 1) / chunk);
  for_each_chunk(m.solid.size(), chunk, n_threads, [&](std::size_t k, std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const auto pts = element_points<2>(m.solid, id, m.points);
      if (min_corner_jacobian<2>(m.solid.type[e], pts.span()) > 0) continue;
      Point<2> c = Point<2>::Zero();
      for (int i = 0; i < pts.n; ++i) c += pts.p[i];
      found[k].push_back({c / pts.n, "an element is inverted"});
    }
  });
  std::vector<Problem> out;
  for (const std::vector<Problem>& f : found) out.insert(out.end(), f.begin(), f.end());
  return out;
}

/// The refusal of a run whose last problems include chains of free edges projecting onto two
/// loops: parts thinner than the quadrants there (Options2d::thin_retry_boost).
struct ThinPartsRefusal : GeometryError {
  using GeometryError::GeometryError;
};

/// The pipeline with the level field's floors up to `floor_boost` levels beyond a given level
/// (CurveBoundary::control_level).
Result2d mesh2d_once(const CurveBoundary& curve, const Options2d& opt, const Progress& progress, double floor_boost) {
  auto say = [&](const std::string& s) {
    if (progress) progress(s);
  };
  keep_freed_arrays_in_heap();
  Result2d r;
  StageTimer clock(r.times);
  RefineOptions ro;
  ro.max_level = opt.max_level;
  ro.max_leaves = opt.max_cells;
  ro.n_threads = opt.n_threads;

  say("quadrant generation: subdividing by the mesh control parameters");
  // A box outside the solid that meets no curve holds no element, whatever the level there:
  // it is not split (the 2:1 balance grades the outside around the solid). The interior and
  // curve quadrants, and so the mesh, are those of the uniform outside; the tree of a glyph
  // was three quarters outside leaves (NimbusSans U0067 at level 11: 16.8 M, 4.3 M inside).
  const ControlFn<2> control = [&](const Box<2>& b) {
    return !opt.split_outside && curve.classify(b) == Side::Out ? 0.0 : curve.control_level(b, floor_boost);
  };
  Orthtree<2> tree = subdivide_by_control(curve.root_box(), control, ro);
  clock.lap("subdivide");
  r.n_subdivided = tree.n_leaves();
  if (opt.keep_stages) r.subdivided = tree;
  say("quadrant generation: " + std::to_string(tree.n_leaves()) + " quadrants; one-level-difference rule");
  BalanceOptions balancing;
  balancing.n_threads = opt.n_threads;  // the same tree for every count
  tree = balance_2to1(tree, BalanceKind::Face, balancing);
  clock.lap("balance");
  r.n_balanced = tree.n_leaves();
  if (opt.keep_stages) r.balanced = tree;

  const CurveMidpoint midpoint = [&](const BoundaryLocation& a, const BoundaryLocation& b) {
    const Loop& loop = curve.loops()[a.patch];
    const double n = static_cast<double>(loop.n_pieces());
    double d = std::fmod(b.param[0] - a.param[0], n);
    if (d < 0) d += n;
    BoundaryLocation w;
    w.patch = a.patch;
    w.param[0] = wrap_parameter(loop, a.param[0] + 0.5 * d);
    return std::make_pair(evaluate(loop, w.param[0]), w);
  };

  for (int attempt = 0;; ++attempt) {
    const bool last = attempt >= opt.max_repairs;
    say("interior quadrants: classifying " + std::to_string(tree.n_leaves()) + " quadrants");
    Flags in = interior_flags(classify(tree, curve, opt.n_threads));
    FreeEdges edges;
    {
      const LeafKeys<2> keys(tree);  // one for both (a key a leaf: its pages were 47% of the
                                     // faults of a glyph run at 8.7 M triangles, built twice)
      r.n_buffer_dropped = apply_buffer(tree, in, curve, opt.buffer, &edges, &keys, opt.n_threads);
      r.n_pinches_dropped = remove_pinches(tree, in, &edges, &keys);
    }
    clock.lap(attempt == 0 ? "classify" : "classify (repair " + std::to_string(attempt) + ")");

    say("boundary quadrants: projecting the free edges onto the curve");
    BoundaryQuadrantOptions bo;
    bo.corners_may_fail = last;
    bo.n_threads = opt.n_threads;
    QuadrantComplexResult bq = build_quadrant_complex(tree, in, curve, bo, &edges);
    r.n_boundary_quadrants = bq.complex.boundary.size();
    clock.lap("boundary quadrants");
    std::vector<Problem> problems = bq.problems;

    FeBeMesh fe;
    if (problems.empty()) {
      say("finite elements: templates");
      // Quad = the mixed mesh smoothed and improved, then split once and optimised.
      const ElementKind base = opt.elements == ElementKind::Quad ? ElementKind::Mixed : opt.elements;
      fe = fe_be_mesh(bq.complex, base, midpoint, opt.n_threads);
      // The complex is kept only for the figures (and the quad split only adds elements): free
      // it before smoothing, the run's memory peak, when they will not be drawn.
      if (!opt.keep_stages || fe.mesh.solid.size() > opt.keep_stages_max_elements) bq.complex = QuadrantComplex();
      clock.lap("templates");
      say("smoothing: " + std::to_string(opt.smoothing_iterations) + " Laplacian iterations");
      SmoothOptions<2> so;
      so.n_iterations = opt.smoothing_iterations;
      so.n_threads = opt.n_threads;
      // The sweeps in slab order, on every thread (core/partitioned_sweep.hpp). In node order
      // they ran on one thread: most 2D visits find the node settled (min_move) and return,
      // and scheduling them on the node order's DAG cost more than the visits (flange at 5.4 M
      // triangles, smoothing 0.45-0.74 s on one thread against 0.68-1.09 s on two).
      so.parts = default_sweep_parts;
      // Rounding noise: a few ulps of the coordinates are ~1e-13 of an edge at level 10 and
      // ~3e-11 at level 17; real moves near the curve are far above it.
      so.min_move = quality_rounding_share;  // 1e-10; the quality pass's too (at_rest)
      so.min_quality = false;  // (not reported)
      std::vector<std::uint8_t> at_rest;
      so.at_rest = &at_rest;
      so.fixed.assign(fe.mesh.points.size(), 0);
      if (opt.slide_boundary) {
        for (std::size_t k = 0; k < fe.where.size(); ++k)
          if (fe.where.locations()[k].kind == BoundaryLocation::Kind::Corner) so.fixed[fe.where.nodes()[k]] = 1;
        so.project = [&](const Point<2>& p) { return Point<2>(curve.closest_point(p).point); };
      } else {
        // The solid's boundary is the BE mesh: its nodes stay, and smooth need not find them.
        for (const std::int32_t v : fe.where.nodes()) so.fixed[v] = 1;
        so.boundary_fixed = true;
      }
      const SmoothStats ss = smooth(fe.mesh, so);
      r.n_smoothing_rejected = ss.moves_rejected;
      if (opt.slide_boundary) {
        for (std::size_t k = 0; k < fe.where.size(); ++k)
          if (BoundaryLocation& w = fe.where.locations()[k]; w.kind != BoundaryLocation::Kind::Corner)
            w = curve.closest_point(fe.mesh.points[fe.where.nodes()[k]]).where;
      }
      clock.lap("smoothing");
      // Interface nodes slide along their own loop, landing exactly on the curve; corners stay.
      std::vector<std::uint8_t> locked;
      auto lock_interface = [&] {
        locked.assign(fe.mesh.points.size(), 0);
        for (std::size_t k = 0; k < fe.where.size(); ++k)
          locked[fe.where.nodes()[k]] =
              fe.where.locations()[k].kind == BoundaryLocation::Kind::Corner || !opt.slide_in_quality_pass ? 1 : 2;
      };
      const SlideFn slide = [&](std::int32_t v, const Point<2>& target) {
        const ClosestPoint<2> cp = curve.closest_point(target);
        BoundaryLocation& w = fe.where.at(v);
        if (cp.where.patch != w.patch || cp.where.kind == BoundaryLocation::Kind::Corner) return fe.mesh.points[v];
        w = cp.where;
        return Point<2>(cp.point);
      };
      // A rejected slide left `where` at the tried point: recompute it from the kept position.
      auto settle_interface = [&] {
        for (std::size_t k = 0; k < fe.where.size(); ++k)
          if (const std::int32_t v = fe.where.nodes()[k]; locked[v] == 2)
            fe.where.locations()[k] = curve.closest_point(fe.mesh.points[v]).where;
      };
      if (opt.improve_rounds > 0) {
        say("quality: edge flips and angle-guarded smoothing");
        lock_interface();
        ImproveOptions io;
        io.rounds = opt.improve_rounds;
        io.slide = slide;
        io.n_threads = opt.n_threads;
        io.at_rest = &at_rest;
        io.measure_min = false;  // (not reported)
        const ImproveStats is = improve_mesh(fe.mesh, locked, io);
        settle_interface();
        r.n_flips = is.flips;
        clock.lap("quality pass");
      }
      if (opt.elements == ElementKind::Quad) {
        say("quadrilaterals: splitting every element once");
        fe = split_to_quads(fe, midpoint);
        clock.lap("quad split");
      }
      // Then every kind: node positions that raise the worst corner angle. Triangles aim at
      // 30 deg (q = 1.5), in triangle and mixed meshes, which they reach on all our data away
      // from the NACA trailing edge. Quads aim at q = 1.25 (within [37.5, 142.5] deg): a higher
      // aim also works on more nodes near a sharp corner, pushing quads just outside its exempt
      // zone to 168 deg (NACA, level 6).
      if (opt.improve_rounds > 0) {
        say("quality: corner-angle optimisation");
        lock_interface();
        AngleOptimiseOptions ao;
        ao.rounds = 2 * opt.improve_rounds;
        ao.target = opt.elements == ElementKind::Tri ? 1.5 : 1.25;
        if (opt.elements == ElementKind::Mixed) ao.triangle_target = 1.5;
        ao.curve_distance = [&](const Point<2>& p) { return curve.closest_point(p).distance; };
        ao.n_threads = opt.n_threads;
        ao.measure_worst = false;  // (not reported)
        r.n_angle_moves = optimise_angles(fe.mesh, locked, ao, slide).moves;
        settle_interface();
        clock.lap("angle optimisation");
      }
      problems = inverted_elements(fe.mesh, opt.n_threads);
    }
    if (problems.empty()) {
      r.stats = bq.stats;
      r.fe = std::move(fe);
      r.stages_kept = opt.keep_stages && r.fe.mesh.solid.size() <= opt.keep_stages_max_elements;
      if (!r.stages_kept) {
        r.subdivided = Orthtree<2>();
        r.balanced = Orthtree<2>();
      } else {
        r.complex = std::move(bq.complex);
        BoundaryQuadrantOptions no_pull = bo;
        no_pull.pull_corners = false;
        r.before_pulling = build_quadrant_complex(tree, in, curve, no_pull, &edges).complex;
      }
      r.interior = std::move(in);
      r.tree = std::move(tree);
      return r;
    }
    Flags flags;
    std::vector<Point<2>> places;
    for (const Problem& pr : problems) places.push_back(pr.where);
    if (last || !mark_around<2>(tree, places, 2.0, opt.max_level, flags)) {
      const std::string why = "the boundary quadrants cannot be built after " + std::to_string(r.n_repairs) +
                              " local refinements (max level " + std::to_string(opt.max_level) + "): " + describe(problems);
      if (std::any_of(problems.begin(), problems.end(), [](const Problem& p) { return p.what == two_loops_problem; }))
        throw ThinPartsRefusal(why);
      throw GeometryError(why);
    }
    ++r.n_repairs;
    r.repaired.insert(r.repaired.end(), problems.begin(), problems.end());
    say("repair " + std::to_string(attempt + 1) + ": refining around " + std::to_string(problems.size()) +
        " place(s): " + describe(problems));
    tree = balance_2to1(refine(tree, flags), BalanceKind::Face, balancing);
    clock.lap("repair refinement");
  }
}

}  // namespace

Result2d mesh2d(const CurveBoundary& curve, const Options2d& opt, const Progress& progress) {
  try {
    return mesh2d_once(curve, opt, progress, CurveBoundary::floor_boost_default);
  } catch (const ThinPartsRefusal& e) {
    // The floors stop floor_boost_default levels beyond a given level (--level, --size, the
    // file's levels): a part thinner than 4 quadrants of that finest level is not resolved, and
    // refining around its problems went on past the repairs allowed (an annulus 2 thick, 80
    // across, at --size 10: refused after 12 repairs; at 9 meshed). Only after such a refusal,
    // so that every mesh made before stays the same; automatic levels have no such stop.
    if (curve.is_automatic() || !(opt.thin_retry_boost > CurveBoundary::floor_boost_default)) throw;
    const std::string rule = "with the thickness rule up to " + std::to_string(static_cast<int>(opt.thin_retry_boost)) +
                             " levels beyond the level asked";
    if (progress) progress(std::string(e.what()) + "; once more " + rule);
    try {
      Result2d r = mesh2d_once(curve, opt, progress, opt.thin_retry_boost);
      r.thin_parts_refined = true;
      return r;
    } catch (const GeometryError& again) {
      throw GeometryError(std::string(e.what()) + "; " + rule + ": " + again.what());
    } catch (const LimitError& again) {  // the finer tree over max_cells: still a bound, named as such
      throw LimitError(std::string(e.what()) + "; " + rule + ": " + again.what());
    }
  }
}

}  // namespace febemesh::dim2
