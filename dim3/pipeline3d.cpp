#include "dim3/pipeline3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/stage_timer.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/mesh3d_try.hpp"
#include "dim3/planar_frame.hpp"

namespace febemesh::dim3 {
namespace {

/// What may stand between a try's refusal and its fallback (uniform_early): a mesh, or none.
using BeforeFallback = std::function<std::optional<Result3d>(const GeometryError&)>;

/// run(opt), and when that throws GeometryError, once more with `fallback` (the same input and
/// the same fallback, so still deterministic), reporting why and setting `dropped`; `before`,
/// when given, first, and its mesh stands if it makes one.
template <typename Run>
Result3d with_fallback(const Run& run, const Options3d& opt, const Options3d& fallback, const std::string& what,
                       bool Result3d::*dropped, const Progress3& progress, const BeforeFallback& before = {}) {
  try {
    return run(opt);
  } catch (const GeometryError& e) {
    if (before)
      if (std::optional<Result3d> r = before(e)) return std::move(*r);
    if (progress) progress(what + ", after: " + e.what());
    Result3d r = run(fallback);
    r.*dropped = true;
    return r;
  }
}

/// What feature snapping does on this surface with these options: nothing (off, or no feature
/// lines), nothing because the surface is faceted (more of its feature lines' ends free than
/// Options3d::faceted_free_ends), or snap.
enum class Snapping { Off, Faceted, Snapped };

Snapping snapping(const SurfaceBoundary& s, const Options3d& opt) {
  if (!opt.snap_features || s.features().n_feature_edges() == 0) return Snapping::Off;
  return s.features().free_end_share() > opt.faceted_free_ends ? Snapping::Faceted : Snapping::Snapped;
}

Result3d mesh3d_features(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  const auto once = [&](const Options3d& o) { return mesh3d_once(s, o, effort, progress); };
  const Snapping how = snapping(s, opt);
  if (how == Snapping::Off) return once(opt);
  // Feature snapping pulls nodes across octants; on coarsely faceted surfaces (every edge a
  // feature: tori of 8 segments) it leaves tetrahedra no node move can unfold, where the plain
  // projection meshes validly.
  Options3d plain = opt;
  plain.snap_features = false;
  if (how == Snapping::Faceted) {
    const double free_ends = s.features().free_end_share();
    if (progress)
      progress("without feature snapping: " + std::to_string(static_cast<int>(std::lround(100.0 * free_ends))) +
               "% of the feature lines' ends are free (a faceted surface)");
    Result3d r = once(plain);
    r.features_dropped = true;
    return r;
  }
  if (opt.features_fallback_last) return once(opt);  // mesh3d_tries falls back, after every try
  return with_fallback(once, opt, plain, "without feature snapping", &Result3d::features_dropped, progress);
}

Result3d mesh3d_buffer(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  const auto features = [&](const Options3d& o) { return mesh3d_features(s, o, effort, progress); };
  if (opt.buffer <= 0 || !opt.retry_without_buffer) return features(opt);
  // The buffer rule drops interior octants near the surface; in a part two octants thick it
  // leaves a slab one octant wide whose rim nodes are nearer the far sheet than their own:
  // their projections run back through the part and fold the boundary octants on that side
  // (measured on anchor L4, experiments/diagnose3d), and refining around them moves the
  // folds. Without the buffer the slab reaches both sheets.
  Options3d plain = opt;
  plain.buffer = 0.0;
  return with_fallback(features, opt, plain, "without the buffer rule", &Result3d::buffer_dropped, progress);
}

}  // namespace

ValidateOptions<3> surface_validation(const SurfaceBoundary& s, int n_threads) {
  ValidateOptions<3> vo;
  vo.n_threads = n_threads;
  if (s.euler_characteristic() % 2 == 0) vo.expected_euler = s.euler_characteristic() / 2;
  vo.boundary_distance = [&s](const Point<3>& p) { return s.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * s.bounding_box().extent().norm();
  return vo;
}

const ValidationReport& validation_of(Result3d& r, const SurfaceBoundary& s, int n_threads) {
  const std::uint64_t hash = content_hash(r.fe.mesh);
  if (!r.validation || r.validation_hash != hash) {
    r.validation = validate(r.fe.mesh, surface_validation(s, n_threads));
    r.validation_hash = hash;
  }
  return *r.validation;
}

namespace {

std::optional<Result3d> uniform_early(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const GeometryError& e,
                                      bool snapped, const Progress3& progress);

Result3d mesh3d_facing(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  const auto buffer = [&](const Options3d& o) { return mesh3d_buffer(s, o, effort, progress); };
  if (!opt.retry_facing) return buffer(opt);
  // Thin lips (fandisk): a node's closest point can lie on the far sheet or run back along the
  // interior octants, folding its boundary octants, and refining moves the folds. The last
  // try admits only projections leaving through every free face of the node and landing on
  // surface facing it, without the buffer rule; interface triangles the fold test still flags
  // (their nodes on sheets whose normals disagree) are kept when the validator accepts the mesh.
  // Measured (fandisk L4, diagnose3d): valid after 3 repairs, 131238 tets, 11.8 deg, 1.6%. Only
  // after the try without the buffer rule (and, without Options3d::buffer_last, the buffer
  // rule's), so that the meshes they make stay the same (anchor L5 is refused with these
  // projection rules and the buffer).
  const Options3d facing = facing_try_options(opt);
  if (!opt.buffer_last || !(opt.buffer > 0) || !opt.retry_without_buffer)
    return with_fallback(buffer, opt, facing, "with facing projections only", &Result3d::facing_projection, progress);
  // Options3d::buffer_last: without the buffer rule, then with facing projections, and with the
  // buffer rule only when both are refused.
  const auto features = [&](const Options3d& o) { return mesh3d_features(s, o, effort, progress); };
  Options3d plain = opt;
  plain.buffer = 0.0;
  try {
    return with_fallback(features, plain, facing, "with facing projections only", &Result3d::facing_projection, progress,
                         [&](const GeometryError& e) { return uniform_early(s, opt, effort, e, false, progress); });
  } catch (const GeometryError& e) {
    if (progress) progress(std::string("with the buffer rule, after: ") + e.what());
    Result3d r = features(opt);
    r.buffer_fallback = true;
    return r;
  }
}

/// mesh3d_facing; with Options3d::features_fallback_last on a surface whose feature lines are
/// snapped to (not faceted), every try with feature snapping first, and only when all of them
/// are refused every try without it, in the same order.
Result3d mesh3d_tries(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  const auto facing = [&](const Options3d& o) { return mesh3d_facing(s, o, effort, progress); };
  if (!opt.features_fallback_last || snapping(s, opt) != Snapping::Snapped) return facing(opt);
  Options3d plain = opt;
  plain.snap_features = false;
  return with_fallback(facing, opt, plain, "without feature snapping, every try", &Result3d::features_dropped, progress,
                       [&](const GeometryError& e) { return uniform_early(s, opt, effort, e, true, progress); });
}

}  // namespace

std::size_t apply_buffer_rules(const Orthtree<3>& t, Flags& in, const SurfaceBoundary& s, const Options3d& opt) {
  std::size_t n = apply_buffer(t, in, s, opt.buffer, opt.n_threads);
  if (opt.flat_buffer > opt.buffer) n += apply_buffer(t, in, s, opt.flat_buffer, opt.n_threads, true);
  return n;
}

Options3d facing_try_options(const Options3d& opt) {
  Options3d facing = opt;
  facing.buffer = 0.0;
  facing.min_outward = 0.3;
  facing.min_facing = 0.3;
  facing.outward_all_faces = true;
  facing.accept_valid_folds = true;
  facing.retry_facing = false;
  // The last try: one repair that makes it worse is not yet the end (Options3d::worse_repairs).
  // Measured (CLI, one thread): fandisk L5 refused -> valid (the 7th repair of its first
  // sub-try, after 25 -> 35 problems at the 6th).
  facing.worse_repairs = std::max(opt.worse_repairs, 1);
  return facing;
}

Options3d thickness_try_options(const Options3d& opt) {
  Options3d thick = opt;
  thick.raise_levels = 0;
  thick.effort = std::min(opt.effort, opt.thin_retry_effort);
  thick.min_effort_octants = 0;
  thick.thickness_cells = opt.refused_thickness_cells;
  thick.buffer = 0.0;  // its one-octant slabs in thin parts project through them (thin retry)
  return thick;
}

bool thickness_try_applies(SurfaceBoundary& s, const Options3d& opt) {
  const double cells = opt.refused_thickness_cells;
  if (!(cells > 0)) return false;
  const double h_feature = s.octant_side(opt.level + 1);
  return s.thin_share(cells * h_feature) > 0;
}

std::string octants_across(double cells) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", cells);
  return std::string(text) + " octants across";
}

namespace {

/// |volume of the solid elements - the surface's| / the surface's.
double volume_error(const Mesh<3>& m, const SurfaceBoundary& s, int n_threads) {
  return std::abs(solid_measure<3>(m, n_threads) - s.volume()) / std::abs(s.volume());
}

/// "12.34% of the volume lost", for the progress report.
std::string volume_lost(double error) {
  char text[64];
  std::snprintf(text, sizeof text, "%.2f%% of the volume lost", 100 * error);
  return text;
}

/// A level raise's options (Options3d::raise_levels): one level finer, one raise fewer, the tries
/// at the finer level as they are at that level (the thickness probe too), refused early rather
/// than after a huge tree (at most min_effort_octants octants). Until session 50 the raise ran
/// without the probe: examples/3d/tee.stl at level 4 (walls 0.6 of an octant) was raised to
/// level 5 and refused there after 38 s, where level 5 asked directly stands at the probe's
/// first tree (1,103,298 tets, 20.00 deg, 0.41% volume error); its level-4 run ended with an
/// invalid mesh of 193 tets (99.6% of the volume lost). Now the raise stands in the same mesh.
Options3d one_level_finer(const Options3d& opt) {
  Options3d finer = opt;
  ++finer.level;
  --finer.raise_levels;
  finer.max_cells = std::min(opt.max_cells, opt.min_effort_octants);
  return finer;
}

/// mesh3d_tries, and when every try is refused although they built on fewer octants than
/// opt.min_effort_octants (a coarse level: the features are a couple of octants across), once
/// more one level finer within that many octants (Result3d::level_raised). Measured: the 4x4x4
/// voxel union of tests/dim3/regressions (seed 5, case 180) is refused at level 3 through every
/// try and valid at levels 4 and 5. A costly refusal (spool L6: millions of octants) stands.
Result3d mesh3d_raised(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const Progress3& progress) {
  try {
    return mesh3d_tries(s, opt, effort, progress);
  } catch (const GeometryError& e) {
    effort.refused_cheaply = effort.used < opt.min_effort_octants;
    if (opt.raise_levels <= 0 || !effort.refused_cheaply) throw;
    if (progress) progress("refused at level " + std::to_string(opt.level) + " (" + e.what() + "): once more at level " +
                           std::to_string(opt.level + 1));
    const Options3d finer = one_level_finer(opt);
    Effort raised;
    raised.limit = opt.min_effort_octants;
    const auto both = [&](const std::exception& finer_error) {
      return GeometryError(std::string(e.what()) + "; at level " + std::to_string(finer.level) + ": " + finer_error.what());
    };
    Result3d r;
    try {
      r = mesh3d_raised(s, finer, raised, progress);
    } catch (const LimitError& limit) {
      throw both(limit);
    } catch (const GeometryError& finer_error) {
      throw both(finer_error);
    }
    effort.used += raised.used;
    r.level_raised += 1;
    return r;
  }
}

}  // namespace

namespace {

/// One try after every other was refused: mesh3d_tries with `o` within its own work bound of
/// o.effort first trees. The mesh (its n_octants_built counting `effort` too), or the refusal's
/// reason in `why`; `built`, when given, receives the octants the try built on either way.
std::optional<Result3d> try_after_refusal(SurfaceBoundary& s, const Options3d& o, const Effort& effort,
                                          std::string& why, const Progress3& progress, std::size_t* built = nullptr) {
  Effort own;
  std::optional<Result3d> t;
  Options3d tried = o;
  tried.uniform_early_faceted = tried.uniform_early_snapped = false;  // a run's own chain only
  try {
    t = mesh3d_tries(s, tried, own, progress);
    t->n_octants_built = effort.used + own.used;
  } catch (const GeometryError& f) {
    why = f.what();
  } catch (const LimitError& f) {
    why = f.what();
  }
  if (built) *built = own.used;
  return t;
}

}  // namespace

/// mesh3d_raised's refusal `e` (after `effort`): when part of the solid is thin, once more with
/// the thickness level (Options3d::refused_thickness_cells), and when that is refused too, once
/// more with the thin parts coarse (Options3d::coarse_thin_after_refusal); when every one is
/// refused, `e` again (the same type), with their reasons.
template <class E>
Result3d after_refusal(SurfaceBoundary& s, const Options3d& opt, const Effort& effort, const E& e,
                       const Progress3& progress) {
  const double cells = opt.refused_thickness_cells;
  if (opt.thickness_cells > 0 || !thickness_try_applies(s, opt)) throw e;
  std::string reasons = e.what(), why;
  // Both tries: no level raise, their own work bound of thin_retry_effort first trees.
  const Options3d thick = thickness_try_options(opt);
  Options3d after = opt;
  after.raise_levels = 0;
  after.effort = thick.effort;
  after.min_effort_octants = 0;
  after.thickness_probe = false;
  if (!effort.thickness_probe_refused.empty()) {
    // Its first tree is the probe's, which did not stand. Measured: rotor L6 spent 272 s of its
    // 1,069 s wall on this try's repairs after the probe's first round had left 6% inverted
    // (refused by its work bound); in 800 survey cases (voxel seeds 4 and 5, tori 11 and 12)
    // this try never stood.
    why = "its first tree is the thickness probe's: " + effort.thickness_probe_refused;
    if (progress)
      progress(std::string("refused (") + e.what() + "): not once more with " + octants_across(cells) +
               " the thin parts (" + why + ")");
  } else {
    if (progress)
      progress(std::string("refused (") + e.what() + "): once more with " + octants_across(cells) +
               " the thin parts, without the buffer rule");
    if (std::optional<Result3d> t = try_after_refusal(s, thick, effort, why, progress)) {
      t->thickness_after_refusal = true;
      return std::move(*t);
    }
  }
  s.set_thickness_level(opt.thickness_cells, opt.level + opt.thickness_extra_levels);
  reasons += "; with " + octants_across(cells) + " the thin parts: " + why;
  if (!opt.coarse_thin_after_refusal) throw E(reasons);
  Options3d coarse = after;
  coarse.island_refinements = 0;
  coarse.thin_cells = 0.0;
  const double feature_extra = s.feature_extra_levels();
  s.set_feature_extra_levels(0.0);
  if (progress)
    progress("refused (" + why + "): once more without the feature level and the thin parts' refinements" +
             " (parts thinner than the octants are not meshed)");
  std::optional<Result3d> c = try_after_refusal(s, coarse, effort, why, progress);
  s.set_feature_extra_levels(feature_extra);
  if (c) {
    c->thin_parts_coarse = true;
    return std::move(*c);
  }
  throw E(reasons + "; without the feature level: " + why);
}

Options3d thin_retry_options(const Options3d& ran, std::size_t first_tree_leaves) {
  Options3d thin = ran;
  thin.thickness_cells = ran.thin_retry_cells;
  thin.buffer = 0.0;
  // No refinement of every octant on the surface for lost topology: on the thickness-refined
  // tree it multiplies the octants (rotor L4: 37927 -> 116145 -> 311522 over the repairs, 2.5
  // CPU minutes, refused), while its first tree's mesh may already lose less. Only while the
  // tree has no interior octant: a plate 0.05 thick at level 4 (octants 0.13, the cap's 0.033)
  // has none at the thickness level's cap, and one refinement more meshes it.
  thin.surface_refinements_empty_only = true;
  // A bounded retry: a few repairs per try, trees of at most 8x the first tree's octants (1M
  // at least), and its own work bound of thin_retry_effort. Unbounded, rotor L5's retry ran for
  // more than 17 CPU minutes without a mesh; past the bounds the first mesh stands.
  thin.max_repairs = std::min(ran.max_repairs, 4);
  thin.max_cells = std::min(ran.max_cells, std::max<std::size_t>(8 * first_tree_leaves, std::size_t{1} << 20));
  thin.effort = std::min(ran.effort, ran.thin_retry_effort);
  thin.min_effort_octants = 0;
  thin.uniform_early_faceted = thin.uniform_early_snapped = false;  // a run's own chain only
  return thin;
}

Options3d thin_parts_try_options(SurfaceBoundary& s, const Options3d& opt, std::size_t first_tree_leaves) {
  Options3d thin = thin_retry_options(opt, first_tree_leaves);
  // The cap of the thickness level where the thin parts need more than level + 2 for their
  // octants across (at most 4 levels more; the try's bounds refuse a tree too large). Measured
  // (a ring r 1, 0.03 thick, 0.3 high, CLI, one thread): refused at levels 4 and 5 with the cap
  // at level + 2 (about one octant across, folds); the try alone with level 8 (diagnose3d
  // --thickness-extra 4): valid at level 4, 1,603,728 tets, 17.89 deg, 36 s.
  const double needed = std::ceil(s.thin_parts_level(thin.thickness_cells, opt.level));
  if (std::isfinite(needed))
    thin.thickness_extra_levels = std::clamp(static_cast<int>(needed) - opt.level, opt.thickness_extra_levels,
                                             opt.thickness_extra_levels + 4);
  // Two levels of repairs below the thin parts' octants (else max(level + extra_levels, the
  // cap): none at the cap), and the run's least work bound (the retry has none: it only
  // improves a mesh; this try is the run's).
  if (opt.max_level < 0) thin.max_level = opt.level + std::max(opt.extra_levels, thin.thickness_extra_levels) + 2;
  thin.min_effort_octants = opt.min_effort_octants;
  return thin;
}

Options3d uniform_try_options(const Options3d& opt) {
  Options3d uniform = opt;
  uniform.extra_levels = 0;
  uniform.raise_levels = 0;
  uniform.in_plane_cosine = opt.uniform_in_plane_cosine;
  return uniform;
}

namespace {

/// The try with the surface at the one level (uniform_try_options), within its own work bound
/// of opt.effort first trees (try_after_refusal); `effort` counts its octants and notes that it
/// ran (Effort::uniform_tried). The mesh (Result3d::surface_uniform), or the refusal's reason
/// in `why`.
std::optional<Result3d> uniform_try(SurfaceBoundary& s, const Options3d& opt, Effort& effort, std::string& why,
                                    const Progress3& progress) {
  effort.uniform_tried = true;
  std::size_t built = 0;
  std::optional<Result3d> r = try_after_refusal(s, uniform_try_options(opt), effort, why, progress, &built);
  effort.used += built;
  if (r) r->surface_uniform = true;
  return r;
}

std::string only_at_level(int level) { return "with the surface at level " + std::to_string(level) + " only"; }

/// The refusal `e` of every other try (after `effort`): once more with the surface at the one
/// level (Options3d::uniform_after_refusal; uniform_try) unless that ran early (uniform_early);
/// refused too, `e` with both reasons.
Result3d uniform_after_refusal(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const GeometryError& e,
                               const Progress3& progress) {
  if (!opt.uniform_after_refusal || opt.extra_levels <= 0) throw e;
  if (!effort.uniform_refused.empty())  // it ran early and was refused
    throw GeometryError(std::string(e.what()) + "; " + only_at_level(opt.level) + ": " + effort.uniform_refused);
  if (progress)
    progress(std::string("refused (") + e.what() + "): once more " + only_at_level(opt.level) +
             " (no curvature or feature levels)");
  std::string why;
  if (std::optional<Result3d> r = uniform_try(s, opt, effort, why, progress)) return std::move(*r);
  throw GeometryError(std::string(e.what()) + "; " + only_at_level(opt.level) + ": " + why);
}

/// The refusal `e` of the first try on a faceted surface (Options3d::uniform_early_faceted) or,
/// `snapped`, of every try with feature snapping on one whose feature lines are snapped to
/// (Options3d::uniform_early_snapped): uniform_try at once (`effort` remembers a refusal, so
/// that uniform_after_refusal does not run it again). Empty where it does not apply or was
/// refused.
std::optional<Result3d> uniform_early(SurfaceBoundary& s, const Options3d& opt, Effort& effort, const GeometryError& e,
                                      bool snapped, const Progress3& progress) {
  const bool applies = snapped ? opt.uniform_early_snapped : opt.uniform_early_faceted && snapping(s, opt) == Snapping::Faceted;
  if (!applies || !opt.uniform_after_refusal || opt.extra_levels <= 0 || effort.uniform_tried) return std::nullopt;
  if (progress)
    progress(std::string("refused (") + e.what() + "): " +
             (snapped ? "every try with feature snapping" : "a faceted surface") + ", so at once " +
             only_at_level(opt.level) + " (no curvature or feature levels)");
  std::string why;
  std::optional<Result3d> r = uniform_try(s, opt, effort, why, progress);
  if (!r) {
    effort.uniform_refused = why;
    if (progress) progress(only_at_level(opt.level) + ": refused (" + why + ")");
  }
  return r;
}

/// mesh3d in the surface's own axes: the tries, the fallbacks after a refusal (unless
/// `draw`: a lattice draw's refusal is its end), the thin retry. `effort` may come with a limit.
Result3d mesh3d_in_axes(SurfaceBoundary& s, const Options3d& opt, Effort& effort, bool draw,
                        const Progress3& progress) {
  Result3d r;
  try {
    r = mesh3d_raised(s, opt, effort, progress);
  } catch (const GeometryError& e) {
    if (draw) return uniform_after_refusal(s, opt, effort, e, progress);
    try {
      return after_refusal(s, opt, effort, e, progress);
    } catch (const GeometryError& f) {
      return uniform_after_refusal(s, opt, effort, f, progress);
    }
  } catch (const LimitError& e) {
    if (draw) throw;
    return after_refusal(s, opt, effort, e, progress);
  }
  r.n_octants_built = effort.used;
  Options3d ran = opt;  // the thickness retry below is at the level the mesh was made at
  ran.level += r.level_raised;
  if (!(ran.thin_retry_cells > 0) || ran.thickness_cells > 0 || r.thickness_early) return r;
  const double error = volume_error(r.fe.mesh, s, opt.n_threads);
  // Or a thin part of little volume left out (Options3d::thin_retry_gap): how far the surface
  // gets from the BE mesh, looked at only where part of the solid is thin.
  const double side = s.octant_side(ran.level);
  const bool by_volume = error > ran.thin_retry_error;
  double gap = 0.0;
  if (!by_volume && ran.thin_retry_gap > 0 && s.thin_share(ran.thin_retry_cells * side) > 0)
    gap = surface_to_be_distance(r.fe.mesh, s);
  if (!by_volume && !(gap > ran.thin_retry_gap * side)) return r;
  const std::string why = by_volume ? "volume error " + std::to_string(100 * error) + "%"
                                    : "the surface " + std::to_string(gap / side) + " octants from the BE mesh";
  // Parts thinner than the octants (rotor's blades, spool's flanges at level 4) have no
  // interior octant and are lost; the mesh is valid but misses them. Once more with the
  // thickness level (thin_retry_cells octants across every part, up to level +
  // thickness_extra_levels) and without the buffer rule, whose one-octant slabs in such parts
  // project through them (diagnose3d: spool L4 raw inverted tets 4167 with it, 1243 without).
  // Only here, so that the meshes that keep their volume (and surface) stay bit for bit the
  // same; the retry stands only when it is valid and loses less (for the gap: gets nearer).
  Options3d thin = thin_retry_options(ran, r.tree.n_leaves());
  if (!effort.thin_early_refused.empty()) {
    if (progress)
      progress(why + ": not once more with " +
               octants_across(thin.thickness_cells) + " the thin parts (refused at the first tree: " +
               effort.thin_early_refused + ")");
    return r;
  }
  if (progress)
    progress(why + ": once more with " + octants_across(thin.thickness_cells) +
             " the thin parts, without the buffer rule");
  Effort thin_effort;
  try {
    Result3d t = mesh3d_tries(s, thin, thin_effort, progress);
    t.n_octants_built = r.n_octants_built + thin_effort.used;
    const ValidationReport& v = validation_of(t, s, opt.n_threads);
    const double t_error = volume_error(t.fe.mesh, s, opt.n_threads);
    const double t_gap = by_volume || !v.valid ? 0.0 : surface_to_be_distance(t.fe.mesh, s);
    if (progress)
      progress("thin parts: the mesh is " + std::string(v.valid ? "valid" : "not valid (" + v.summary() + ")") +
               ", volume error " + std::to_string(100 * t_error) + "%" +
               (by_volume || !v.valid ? "" : ", the surface " + std::to_string(t_gap / side) + " octants from it"));
    if (v.valid && (by_volume ? t_error < error : t_gap < gap && t_error <= std::max(error, ran.thin_retry_error))) {
      t.thickness_refined = true;
      t.level_raised = r.level_raised;
      std::vector<StageTime3> times = std::move(r.times);
      times.insert(times.end(), t.times.begin(), t.times.end());
      t.times = std::move(times);
      return t;
    }
  } catch (const GeometryError& e) {
    if (progress) progress(std::string("thin parts: refused (") + e.what() + "); keeping the first mesh");
  } catch (const LimitError& e) {
    if (progress) progress(std::string("thin parts: over the retry's bounds (") + e.what() + "); keeping the first mesh");
  }
  s.set_thickness_level(ran.thickness_cells, ran.level + ran.thickness_extra_levels);
  r.n_octants_built += thin_effort.used;
  return r;
}

/// One run of mesh3d_in_axes on a lattice, and what the draws rank it by.
struct Drawn {
  std::optional<Result3d> r;  ///< empty: refused
  std::string why;            ///< the refusal's reason
  bool limit_error = false;   ///< refused by a bound (LimitError), not by the geometry
  Effort effort;
  int rank = 3;  ///< 0 not degraded, 1 degraded, 2 not valid, 3 refused
  bool volume_only = false;  ///< degraded by the volume it lost, and by nothing else
  bool in_frame = false;     ///< meshed in the frame of the planar faces
  double min_deg = 0.0;      ///< its smallest dihedral angle
  double error = std::numeric_limits<double>::infinity();  ///< volume error
  std::string degraded;                                   ///< how, for the progress report
  int draw = 0;                                           ///< lattice_draw_shift(draw)
  int raised = 0;                                         ///< levels finer than asked (run_drawn's `raised`)
};

/// mesh3d_in_axes on `s` with its root cube shifted by lattice_draw_shift(k), within `limit`
/// octants (0: the work bound of the run's first tree), ranked on `s` as meshed. Draws and
/// retries (`retry`) make no mesh after a refusal (mesh3d_in_axes' `draw`). `raised`: `opt` is
/// that many levels finer than the level asked (Result3d::level_raised).
Drawn run_drawn(SurfaceBoundary& s, const Options3d& opt, int k, std::size_t limit, std::string limit_origin,
                const Progress3& progress, bool retry = false, int raised = 0) {
  Drawn d;
  d.draw = k;
  d.raised = raised;
  d.effort.limit = limit;
  d.effort.limit_origin = std::move(limit_origin);
  const P3 shift0 = s.root_shift();
  s.set_root_shift(shift0 + lattice_draw_shift(k));
  Options3d o = opt;
  if (k > 0) o.raise_levels = 0;  // a level raise is degraded anyway
  try {
    Result3d r = mesh3d_in_axes(s, o, d.effort, k > 0 || retry, progress);
    r.level_raised += raised;
    // Timed as stages of their own (report.json timings_s), not left in what the CLI counts
    // as the time of the tries not kept.
    StageTimer clock{r.times};
    const ValidationReport& v = validation_of(r, s, opt.n_threads);
    d.error = volume_error(r.fe.mesh, s, opt.n_threads);
    clock.lap("validation");
    r.quality = summarize_quality(r.fe.mesh, 10.0, opt.n_threads);
    r.quality_hash = r.validation_hash;  // validation_of's hash of this mesh
    clock.lap("quality summary");
    const double min_deg = r.quality->min_angle_deg;
    d.min_deg = min_deg;
    if (r.level_raised > 0) d.degraded = "one level finer than asked";
    else if (r.thin_parts_coarse) d.degraded = "the thin parts left out";
    else if (r.buffer_fallback) d.degraded = "only the buffer rule's try stood";
    else if (min_deg < opt.draw_min_dihedral_deg) d.degraded = "a dihedral angle of " + std::to_string(min_deg) + " deg";
    else if (d.error > opt.draw_max_volume_error) d.degraded = volume_lost(d.error), d.volume_only = v.valid;
    d.rank = !v.valid ? 2 : d.degraded.empty() ? 0 : 1;
    if (!v.valid) d.degraded = "not valid (" + v.summary() + ")";
    r.lattice_draw = k;
    d.r = std::move(r);
  } catch (const GeometryError& e) {
    d.why = e.what();
  } catch (const LimitError& e) {
    d.why = e.what();
    d.limit_error = true;
  }
  s.set_root_shift(shift0);
  return d;
}

/// Result3d::level, root_scale and cell_size of a run on `s` at `level`.
void set_level_of(Result3d& r, const SurfaceBoundary& s, int level) {
  r.level = level;
  r.root_scale = s.root_scale();
  r.cell_size = s.octant_side(level);
}

/// What is left of a draw's work bound for the next one (0 when nothing is: no draw).
std::size_t left_of(const Effort& e) { return e.limit > e.used ? e.limit - e.used : 0; }

}  // namespace

P3 lattice_draw_shift(int k) {
  // Shares of the root cube's side: a hundredth or so, not a ratio of small integers, so that
  // no lattice plane of levels up to 9 comes back where it was. Measured (level 5, fandisk
  // turned by two random rotations and by 180 degrees about x; session 34): the first shift
  // made the two turned ones valid in their frame at 19.00 and 20.29 deg (refused there
  // without it), the second the 180-degree one at 15.29 deg (thin parts left out without it,
  // 5.98 deg with the first shift).
  if (k == 1) return P3(0.011, 0.007, 0.013);
  if (k == 2) return P3(-0.009, 0.015, -0.012);
  return P3::Zero();
}

Result3d mesh3d(SurfaceBoundary& s, const Options3d& opt_in, const Progress3& progress) {
  // Options3d::size: each surface meshed (the given one, the one turned into its frame, whose
  // bounding box differs) at its own level and root scale.
  const auto sized = [&](SurfaceBoundary& on, const char* where) {
    Options3d o = opt_in;
    if (opt_in.size > 0) {
      const SizedLevel sl = level_for_size<3>(on.bounding_box(), opt_in.size);
      on.set_root_scale(sl.root_scale);
      o.level = sl.level;
      if (progress) {
        char text[160];
        std::snprintf(text, sizeof text, "size %g%s: level %d in a root cube %.4gx the default (%g across)", opt_in.size,
                      where, sl.level, sl.root_scale, on.root_box().extent()[0]);
        progress(text);
      }
    }
    return o;
  };
  const Options3d opt = sized(s, "");
  PlanarFrame frame = planar_frame(s.surface());
  const bool turn = opt.align_planar_faces && frame.turned;
  std::optional<SurfaceBoundary> turned;
  if (turn) {
    if (progress) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "planar faces: %.0f%% of the area on planes square to the frame's axes, %.0f%% to the given ones: "
                    "meshing in that frame",
                    100 * frame.share_frame, 100 * frame.share_given);
      progress(text);
    }
    turned.emplace(turned_surface(s.surface(), frame.to_frame), s.options());
  }
  const Options3d opt_frame = turn ? sized(*turned, " in the frame") : opt;
  // The runs in order: (in the frame?, draw). Each stands when it is not degraded; the draws
  // of one axes share its work bound.
  struct Plan {
    bool in_frame;
    int draw;
  };
  // In a frame, its first draw only, then the given axes: flat faces a little off the lattice
  // planes make flat boundary octants, which a face at an angle does not. Measured, 13 of 400
  // voxel unions of the survey (seeds 4 and 5, level 3) were refused in their frame and none in
  // their given axes (session 33, one lattice).
  const int draws = turn ? std::min(opt.lattice_draws, 1) : opt.lattice_draws;
  // A refusal at the level asked, with lattice draws to come: the draws at that level first,
  // and one level finer (Options3d::raise_levels) only when none of them stands undegraded; the
  // best of all the runs then stands, as before. The raise, made first, cost the most where a
  // draw then stood anyway (a raised mesh is degraded): fandisk scaled by 10^4 (or 10^-4),
  // level 4, refused there on its first lattice, spent 20 of its 32.6 s (34.1 s) one level
  // finer before the first draw stood at level 4. The first run now goes on at its level
  // after the refusal (the thickness and coarse tries, mesh3d_in_axes) instead.
  // In the frame of the planar faces the same holds for the frame's first run (its draw
  // follows; the given axes' run, last and without draws, raises as before): fandisk turned at
  // random (seed 42, the fourth of six) spent 29 of its 42.4 s one level finer before its draw
  // in the frame stood.
  const bool raise_after_draws = draws > 0 && opt.raise_levels > 0;
  std::vector<Plan> plan{{turn, 0}};
  for (int k = 1; k <= draws; ++k) plan.push_back({turn, k});
  if (turn) plan.push_back({false, 0});
  // The surface and options of a run in the frame or in the given axes.
  const auto surface_of = [&](bool in_frame) -> SurfaceBoundary& { return in_frame ? *turned : s; };
  const auto options_of = [&](bool in_frame) -> const Options3d& { return in_frame ? opt_frame : opt; };
  // A run just made: where it was made, its level, and its mesh back in the given axes with
  // what its frame was.
  const auto settle = [&](Drawn& d, bool in_frame) {
    d.in_frame = in_frame;
    if (!d.r) return;
    set_level_of(*d.r, surface_of(in_frame), options_of(in_frame).level);
    d.r->frame = frame;
    if (in_frame) {
      // Back to the given axes (a rotation: the same volumes, angles and Jacobians up to
      // rounding); the report was of the turned mesh against the turned surface.
      const Eigen::Matrix3d back = frame.to_frame.transpose();
      for (P3& q : d.r->fe.mesh.points) q = back * q;
      d.r->validation.reset();
      d.r->validation_hash = 0;
      d.r->quality.reset();
      d.r->quality_hash = 0;
    } else {
      d.r->frame.turned = false;  // share_frame still says what the frame would have had
      d.r->frame.to_frame = Eigen::Matrix3d::Identity();
      d.r->frame_refused = turn;
    }
  };
  std::vector<Drawn> runs;
  std::size_t best = 0;
  // Of the runs so far: the lowest rank, then the least volume lost, then the first.
  const auto rank_last = [&] {
    const Drawn& d = runs.back();
    if (d.rank < runs[best].rank || (d.rank == runs[best].rank && d.error < runs[best].error)) best = runs.size() - 1;
  };
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const Plan& p = plan[i];
    std::size_t limit = 0;
    std::string origin;
    if (p.draw > 0) {
      limit = left_of(runs.back().effort);
      origin = runs.back().effort.limit_origin.empty() ? "what the runs before it left of the work bound"
                                                       : runs.back().effort.limit_origin;
      // The first draw after a run of these axes that lost only volume: at most
      // volume_draw_effort x that run's octants, which the next draw shares.
      const Drawn& first = runs.back();  // (draw 0 of these axes, when p.draw is 1)
      const double cap = opt.volume_draw_effort * static_cast<double>(first.effort.used);
      if (p.draw == 1 && first.volume_only && opt.volume_draw_effort > 0 && cap < static_cast<double>(limit)) {
        limit = static_cast<std::size_t>(cap);
        char text[160];
        std::snprintf(text, sizeof text, "%gx the octants of the first run, which lost only volume", opt.volume_draw_effort);
        origin = text;
      }
      if (limit == 0) {
        // (Nothing to say after a run refused before its first tree, the octree's size: a
        // draw's tree is as large.)
        const bool before_any_tree = !runs.back().r && runs.back().effort.limit == 0;
        if (progress && !before_any_tree) {
          const Drawn& last = runs.back();
          progress((last.r || last.draw == 0 ? std::string()
                                             : "lattice draw " + std::to_string(last.draw) + ": refused (" + last.why + "); ") +
                   "lattice draw " + std::to_string(p.draw) + ": no work bound left; not made");
        }
        continue;
      }
    }
    if (i > 0 && progress) {
      const Drawn& last = runs.back();
      const std::string what = last.r ? last.degraded : "refused (" + last.why + ")";
      const P3 shift = lattice_draw_shift(p.draw);
      char by[96];
      std::snprintf(by, sizeof by, "(%g, %g, %g)", shift.x(), shift.y(), shift.z());
      if (p.draw > 0)
        progress(what + ": once more with the lattice shifted by " + by + " of the root's side" +
                 (p.in_frame ? ", in the frame" : ""));
      else
        progress("in the frame of the planar faces: " + what + "; once more in the given axes");
    }
    Options3d o = options_of(p.in_frame);
    if (raise_after_draws && i == 0) o.raise_levels = 0;
    // A draw after a run whose tries with the curvature and feature levels were refused starts
    // with the surface at the one level (Options3d::uniform_after_refusal), as that run went on:
    // the refused tries cost the most (examples/3d/flange.stl level 6: 89 s of its first draw's
    // 95 s; started there, the draw made the same mesh in 7.5 s; docs/measurements.md, session
    // 51).
    // (Not after a run whose early try at the one level was refused and whose later tries stood:
    // Options3d::uniform_early_faceted.)
    const bool uniform_draw = p.draw > 0 && !runs.empty() && runs.back().effort.uniform_tried &&
                              (!runs.back().r || runs.back().r->surface_uniform) && o.extra_levels > 0;
    if (uniform_draw) {
      o = uniform_try_options(o);
      if (progress) progress("lattice draw " + std::to_string(p.draw) + ": with the surface at level " +
                             std::to_string(o.level) + " only, as the run before it went on");
    }
    runs.push_back(run_drawn(surface_of(p.in_frame), o, p.draw, limit, origin, progress));
    if (uniform_draw) {
      runs.back().effort.uniform_tried = true;
      if (runs.back().r) runs.back().r->surface_uniform = true;
    }
    settle(runs.back(), p.in_frame);
    rank_last();
    if (runs.back().rank == 0) break;
  }
  const int n_runs = static_cast<int>(runs.size());  // the lattice's runs (Result3d::lattice_draws_run)
  if (raise_after_draws && runs[best].rank >= 1 && runs[0].effort.refused_cheaply) {
    // The raise mesh3d_raised makes, in the first run's axes: its tries one level finer within
    // min_effort_octants.
    const bool in_frame = plan[0].in_frame;
    const Options3d finer = one_level_finer(options_of(in_frame));
    if (progress)
      progress("no run at level " + std::to_string(finer.level - 1) + " stands undegraded (" + std::to_string(n_runs) +
               " run(s), the first refused there): once more at level " + std::to_string(finer.level) +
               (in_frame ? ", in the frame" : ""));
    runs.push_back(run_drawn(surface_of(in_frame), finer, 0, finer.min_effort_octants,
                             "the bound of a level raise (min_effort_octants)", progress, true, 1));
    settle(runs.back(), in_frame);
    rank_last();
  }
  Drawn& b = runs[best];
  if (!b.r) {
    // Every run refused: the first run's refusal (the same type), with the others' reasons.
    std::string reasons = runs[0].why;
    for (std::size_t i = 1; i < runs.size(); ++i)
      reasons += std::string("; ") +
                 (runs[i].raised > 0  ? "at level " + std::to_string(options_of(runs[i].in_frame).level + runs[i].raised)
                  : runs[i].draw > 0 ? "lattice draw " + std::to_string(runs[i].draw)
                                     : std::string("in the given axes")) +
                 ": " + runs[i].why;
    if (turn) reasons = "in the frame of the planar faces: " + reasons;
    if (runs[0].limit_error) throw LimitError(reasons);
    throw GeometryError(reasons);
  }
  if (runs.size() > 1 && progress) {
    const std::string how = b.degraded.empty() ? std::string("not degraded") : b.degraded, lost = volume_lost(b.error);
    progress("of " + std::to_string(runs.size()) + " runs, run " + std::to_string(best + 1) + " stands (" +
             (how == lost ? how : how + ", " + lost) + ")");
  }
  // The runs made after the first, whichever stands (a run's own index when it was made).
  b.r->lattice_draws_run = n_runs - 1;
  if (!(b.rank <= 1 && b.min_deg < opt.flat_retry_below_deg && opt.flat_buffer < opt.flat_retry_buffer))
    return std::move(*b.r);

  // Options3d::flat_retry_below_deg: once more on the same lattice with the flat buffer.
  Options3d f = options_of(b.in_frame);
  f.flat_buffer = opt.flat_retry_buffer;
  f.raise_levels = 0;  // (degraded anyway)
  // No retry for thin parts inside it: where the flat buffer leaves a thin part without
  // interior octants the mesh loses it and does not stand; that retry took spool L5 o21 from
  // 13.8 to 62.6 s for a mesh that did not stand.
  f.thin_retry_cells = 0;
  const std::size_t limit = std::max<std::size_t>(1, b.effort.used);
  if (progress) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "a dihedral angle of %.2f deg, under %g: once more without the interior octants whose faces lie flat "
                  "within %g of their size of the surface",
                  b.min_deg, opt.flat_retry_below_deg, opt.flat_retry_buffer);
    progress(text);
  }
  Drawn retry = run_drawn(surface_of(b.in_frame), f, b.draw, limit, "the octants of the run it retries", progress, true);
  settle(retry, b.in_frame);
  const bool better = retry.r && (retry.rank < b.rank || (retry.rank == b.rank && retry.min_deg > b.min_deg &&
                                                          retry.error <= std::max(b.error, opt.draw_max_volume_error)));
  if (progress) {
    char deg[32];
    std::snprintf(deg, sizeof deg, "%.2f deg", retry.min_deg);
    progress(!retry.r ? "flat buffer: refused (" + retry.why + "); the mesh before it stands"
                      : "flat buffer: " + (retry.degraded.empty() ? std::string("not degraded") : retry.degraded) + ", " + deg +
                            ", " + volume_lost(retry.error) + "; " + (better ? "it stands" : "the mesh before it stands"));
  }
  Drawn& kept = better ? retry : b;
  kept.r->lattice_draws_run = n_runs - 1;
  kept.r->flat_retry_made = true;
  kept.r->flat_retry = better;
  return std::move(*kept.r);
}

}  // namespace febemesh::dim3
