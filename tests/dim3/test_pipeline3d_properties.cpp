// Property-based validity of the whole 3D pipeline (issue 5) on random closed surfaces
// (surface_generators.hpp: the kinds, the shrinking). CI budget: a few cases per property, the
// whole dim3_property ctest well under a minute in Release; FEBEMESH_PROPERTY_CASES=N runs more.
// A failure prints the seed (replay with RC_PARAMS="seed=S") and the shrunk case as an OFF file,
// which goes to tests/dim3/regressions/ (replayed at the end of this file, not as [property]).
//
// Every family is asserted hard: perturbed icospheres of 320 triangles (300 local cases) and of
// 80 or 320 (800 local cases, session 8); tori (600 survey cases over seeds 11-13, sessions
// 11-12) and voxel unions (599 of 600 over seeds 4-6; the one failure is kept in
// regressions/mayfail-*.off); the comments at each say what their surveys found and what was
// fixed. The hidden "[.survey]" case counts a family's failures over many cases without stopping.

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/read_msh.hpp"
#include "core/validate.hpp"
#include "core/write_msh.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface_checks.hpp"
#include "property.hpp"
#include "surface_generators.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
using febemesh::test::ShapeKind;
using febemesh::test::SurfaceSpec;
namespace fs = std::filesystem;

namespace {

struct Outcome3 {
  Result3d r;
  ValidationReport v;
  double surface_volume = 0.0;  ///< enclosed by the input triangles
  double fe_volume = 0.0;       ///< sum of the tetrahedra
  double be_volume = 0.0;       ///< enclosed by the BE triangles (divergence theorem)
  double round_off = 0.0;       ///< bound on |fe_volume - be_volume| from floating point alone
  double max_node_distance = 0.0;
  double tolerance = 0.0;       ///< 1e-10 of the bounding-box diagonal
  bool only_tets = true;
};

double det3(const P3& a, const P3& b, const P3& c) { return a.dot(b.cross(c)); }

/// Meshes `surface` (validated and oriented here, as the CLI does) at `level` and measures it;
/// with `given_axes`, in the surface's own axes (Options3d::align_planar_faces off). `said`
/// collects the progress messages.
Outcome3 run_surface(Surface surface, int level, bool given_axes = false, int lattice_draws = Options3d{}.lattice_draws,
                     double draw_below = Options3d{}.draw_min_dihedral_deg,
                     double draw_lost = Options3d{}.draw_max_volume_error,
                     double flat_retry_below = Options3d{}.flat_retry_below_deg, double size_share = 0.0,
                     std::vector<std::string>* said = nullptr) {
  AabbTree tree = validate_surface(surface, "generated");
  SurfaceBoundary s(std::move(surface), std::move(tree));
  Options3d opt;
  opt.level = level;
  // --size: this share of the default cube's octant at `level` (Options3d::size).
  if (size_share > 0) opt.size = size_share * s.root_box().extent()[0] / std::ldexp(1.0, level);
  opt.align_planar_faces = !given_axes;
  opt.lattice_draws = lattice_draws;
  opt.draw_min_dihedral_deg = draw_below;
  opt.draw_max_volume_error = draw_lost;
  opt.flat_retry_below_deg = flat_retry_below;
  const Progress3 progress = [said](const std::string& m) {
    if (said) said->push_back(m);
  };
  Outcome3 out{mesh3d(s, opt, progress), {}};
  const Mesh<3>& m = out.r.fe.mesh;
  const Box<3> bb = s.bounding_box();
  out.tolerance = 1e-10 * bb.extent().norm();
  ValidateOptions<3> vo;
  vo.expected_euler = s.euler_characteristic() / 2;  // a solid's Euler characteristic is half its boundary's
  vo.boundary_distance = [&](const Point<3>& p) { return s.closest_point(p).distance; };
  vo.boundary_tolerance = out.tolerance;
  out.v = validate<3>(m, vo);
  out.max_node_distance = out.v.max_boundary_distance;
  out.surface_volume = s.volume();
  // Both volumes relative to the box centre, so that a far translation cancels nothing.
  const P3 o = 0.5 * (bb.lo + bb.hi);
  double magnitude = 0.0;  // sum of |term|: round-off of a sum is eps times it, per operation
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    if (m.solid.type[e] != ElemType::Tet4) {
      out.only_tets = false;
      continue;
    }
    const VertexId* n = m.solid.nodes(id);
    const P3 a = m.point(n[0]) - o, b = m.point(n[1]) - o, c = m.point(n[2]) - o, d = m.point(n[3]) - o;
    const double vol = det3(b - a, c - a, d - a) / 6.0;
    out.fe_volume += vol;
    magnitude += (b - a).norm() * (c - a).norm() * (d - a).norm() / 6.0;
  }
  double be_magnitude = 0.0;
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* n = m.interface.nodes(id);
    const P3 a = m.point(n[0]) - o, b = m.point(n[1]) - o, c = m.point(n[2]) - o;
    out.be_volume += det3(a, b, c) / 6.0;
    be_magnitude += a.norm() * b.norm() * c.norm() / 6.0;
  }
  // A determinant of three differences is exact to ~16 ulps of the product of the norms; the
  // sum adds one rounding per term of at most the partial sum.
  const double eps = std::numeric_limits<double>::epsilon();
  out.round_off = 32.0 * eps * (magnitude + be_magnitude) +
                  eps * double(m.solid.size() + m.interface.size()) * std::abs(out.be_volume);
  return out;
}

/// What the cases measured, printed after each property.
struct Tally {
  long cases = 0, refused = 0, invalid = 0;
  double max_volume_gap = 0.0;      ///< |fe - be| / round-off bound
  double max_node_distance_rel = 0.0;
  double max_case_seconds = 0.0;
  void print(const char* what) const {
    std::printf("[property] %s: %ld runs, %ld refused (GeometryError/LimitError), %ld invalid, "
                "max |FE-BE volume| %.3g of its round-off bound, max interface node distance %.3g of the "
                "diagonal, slowest run %.3g s\n",
                what, cases, refused, invalid, max_volume_gap, max_node_distance_rel, max_case_seconds);
  }
};

Outcome3 run_case(const SurfaceSpec& spec, int level, Tally& tally, bool given_axes = false, double size_share = 0.0) {
  RC_LOG() << test::describe(spec) << " at level " << level << (given_axes ? " in its given axes" : "");
  if (size_share > 0) RC_LOG() << ", size " << size_share << " of its octant";
  RC_LOG() << "\n";
  ++tally.cases;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    Outcome3 out = run_surface(test::to_surface(spec), level, given_axes, Options3d{}.lattice_draws,
                               Options3d{}.draw_min_dihedral_deg, Options3d{}.draw_max_volume_error,
                               Options3d{}.flat_retry_below_deg, size_share);
    tally.max_case_seconds = std::max(
        tally.max_case_seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!out.v.valid) ++tally.invalid;
    if (out.round_off > 0.0)
      tally.max_volume_gap = std::max(tally.max_volume_gap, std::abs(out.fe_volume - out.be_volume) / out.round_off);
    tally.max_node_distance_rel = std::max(tally.max_node_distance_rel, out.max_node_distance / out.tolerance * 1e-10);
    return out;
  } catch (const GeometryError& e) {
    ++tally.refused;
    RC_FAIL(std::string("GeometryError: ") + e.what());
  } catch (const LimitError& e) {
    ++tally.refused;
    RC_FAIL(std::string("LimitError: ") + e.what());
  }
}

/// The validity contract on one output.
void check_valid(const Outcome3& out) {
  RC_TAG(out.v.valid ? "valid" : "INVALID");
  if (!out.v.valid) RC_FAIL(out.v.summary());
  RC_ASSERT(out.r.fe.mesh.interface.size() > 0u);
  RC_ASSERT(out.only_tets);
  // Interface nodes on the surface within 1e-10 of the size (validate checks it too).
  RC_ASSERT(out.max_node_distance <= out.tolerance);
  // FE volume == volume enclosed by the BE triangles, to round-off.
  RC_LOG() << "FE volume " << out.fe_volume << " BE volume " << out.be_volume << " bound " << out.round_off << "\n";
  RC_ASSERT(std::abs(out.fe_volume - out.be_volume) <= out.round_off);
  RC_ASSERT(out.fe_volume > 0.0);
}

void validity_property(const char* what, int ci_cases, const rc::Gen<SurfaceSpec>& gen, int level) {
  Tally tally;
  const std::string description =
      std::string("whole 3D pipeline output is valid, ") + what + " at level " + std::to_string(level);
  // Half the cases in their given axes: a turned voxel union is meshed in the frame of its
  // faces by default (Options3d::align_planar_faces), and the octants cut at an angle are still
  // what a curved part (and a part with --given-axes) gets.
  auto property = [&] {
    const SurfaceSpec spec = *gen;
    const bool given_axes = *rc::gen::arbitrary<bool>();
    RC_TAG(given_axes ? "given axes" : "default axes");
    check_valid(run_case(spec, level, tally, given_axes));
  };
  test::prop(description, ci_cases, property);
  tally.print(what);
}

}  // namespace

TEST_CASE("3D pipeline output is valid on perturbed spheres", "[property][pipeline3d]") {
  validity_property("perturbed spheres (320 triangles)", 8, test::gen_sphere_spec(2), 3);
}

// Coarse icospheres (80 triangles, so dihedral angles up to ~40 degrees at the perturbed bumps):
// the session 2 shrunk case (regressions/sphere-coarse-inverted-element.off) is fixed. Session 8
// survey (FEBEMESH_SURVEY=sphere1): 100 cases at seed 1 and 400 at seed 2 all valid before the
// island trial, 300 at seed 5 all valid after it; asserted hard since.
TEST_CASE("3D pipeline output is valid on coarse perturbed spheres", "[property][pipeline3d]") {
  validity_property("perturbed spheres (80 or 320 triangles)", 4, test::gen_sphere_spec(1), 3);
}

// Tori: session 2 failed at case 49 (inverted elements, shrunk to regressions/torus-inverted-
// element.off, now fixed by the fold guard). Session 3 fixed two more shrunk cases (a thin ring
// losing its handle: torus-thin-ring-euler.off; feature snapping on a 12x8 torus:
// torus-12x8-feature-snap-inverted.off). Session 8 (survey below, seed 3, 400 requested): 8 of
// the first 286 were invalid, all Euler 1 instead of 0 (the handle lost). 7 had islands at
// level 3 (the whole tube two octants thick) whose refinement the share limit skipped, and the
// fallback (refine every surface octant) folds; the island refinement is now tried above the
// limit (regressions/torus-28x16-islands-over-share-limit.off); the same 400 cases then fail
// once: the 8th, a 12x8 torus with no islands but Euler 1 on its first tree, still goes through
// the surface refinement that folds and keeps the coarse mesh with the wrong topology
// (regressions/torus-12x8-topology-refinement-folds.off), so still [!mayfail]. Session 9: that
// case is valid since the thickness retry (its first mesh loses more than 5%; CLI: valid, 7968
// tets, 19.6 deg, 7.66% lost), and moves to the regressions that must pass.
// Session 11 (survey, 200 cases each): seed 11 all valid; seed 12 case 195 (24x14, level 3)
// returned the mesh saved before a failed topology refinement, Euler 1 instead of 0; such a
// mesh is no longer restored (regressions/torus-seed12-case195-euler.off). Session 12: seed 13,
// 200 of 200 valid; 600 cases over seeds 11-13 with one failure, since fixed: asserted hard.
TEST_CASE("3D pipeline output is valid on tori", "[property][pipeline3d]") {
  validity_property("tori", 4, test::gen_torus_spec(), 3);
}

// Voxel unions: the rotated cube's 2 hanging nodes were a fold of the surface mesh (fixed in
// session 3: folded interface triangles count as bad elements; regressions/voxel-cube-rotated-
// hanging-nodes.off). Session 8 (survey below): seed 1, 100 cases all valid; seed 4, 3 of the
// first 182 fail: two refused (inverted tetrahedra the untangling cannot fix, and refining makes
// more: regressions/mayfail-voxel-notched-cube-inverted.off, 7 of 8 cells of a 2x2x2 grid) and
// one invalid (2 hanging nodes on a 4x4x4 union), so [!mayfail]. After the island trial the same
// three fail, one of them (case 99) now invalid instead of refused: in the last try the trial
// removed its islands, then Euler 0 (expected 1) sent it to the surface refinement that folds,
// which keeps the coarse mesh with the wrong topology (as the 12x8 torus above). Cases 182-199
// fail 4 times after it; rerun with the code before it, 182, 190 and 199 fail the same way, but
// 185 was valid (54154 tets, 11.4 deg, 1 repair) and is refused after it (16 inverted elements
// after 2 repairs): a regression of the island trial, kept as regressions/mayfail-voxel-island-
// trial-refused.off.
// Session 11: the notched cube's inverted tetrahedron was a fin (templates3d cancel_fins: two
// back-to-back triangles of one boundary octant at the notch's concave corner, where a face
// corner's two neighbours project to one surface point), now valid on its first tree and kept
// as regressions/voxel-notched-cube-fin.off; and case 194 (a 4x4x4 union) was accepted with a
// hanging node where two sheets meet on a concave feature line, now refined around since the
// pipeline checks the tetrahedra at the surface for contacts before it accepts a mesh
// (regressions/voxel-hanging-node-concave-edge.off). The island-trial case (185) is valid since
// the last try may take one repair that makes things worse (session h1): regressions/voxel-
// island-trial.off. The seed-4 survey's 200 cases then all pass; seed 5: 199 of 200, case
// 180 (a 4x4x4 union, level 3) refused, inverted tets at several sheared boundary octants
// through every try (regressions/voxel-seed5-case180-level-raised.off).
// Session 12: seed 6, 200 of 200 valid, so 599 of 600 over seeds 4-6. Asserted hard: a change
// that breaks a case fails the suite. Case 180's leftover inverted tets at level 3 sit in
// boundary octants with a corner whose projection runs against the octant's face, cos -0.36
// to -0.8, chosen for another free face of its node (in the facing try, in octants with
// projections 2.5-6.4 face sizes long); since session 15 a refusal that cheap is meshed one
// level finer (Options3d::raise_levels), where it is valid.
TEST_CASE("3D pipeline output is valid on voxel unions", "[property][pipeline3d]") {
  validity_property("voxel unions", 4, test::gen_voxel_spec(), 3);
}

// --size (Options3d::size): tori and voxel unions at 1.5 to 2 times the default cube's level-3
// octant, that is level 3 in a root cube 1.5x to 2x the default: lattices the levels alone
// never give; the same contract.
TEST_CASE("3D pipeline output is valid at sizes between the levels (--size)", "[property][pipeline3d][size]") {
  Tally tally;
  test::prop("whole 3D pipeline output is valid at a size between the levels", 6, [&] {
    const SurfaceSpec spec = *rc::gen::oneOf(test::gen_torus_spec(), test::gen_voxel_spec());
    const double share = 1.5 + *rc::gen::inRange(0, 500) / 1000.0;  // of the level-3 octant
    check_valid(run_case(spec, 3, tally, *rc::gen::arbitrary<bool>(), share));
  });
  tally.print("tori and voxel unions at sizes between the levels");
}

TEST_CASE("3D pipeline is deterministic and its MSH reads back the same", "[property][pipeline3d]") {
  Tally tally;
  test::prop("same msh bytes twice; write + read back gives the same mesh", 3, [&] {
    const SurfaceSpec spec = *test::gen_sphere_spec(2);
    const Outcome3 a = run_case(spec, 3, tally);
    const Outcome3 b = run_case(spec, 3, tally);
    const std::string msh = msh_string<3>(a.r.fe.mesh);
    RC_ASSERT(msh == msh_string<3>(b.r.fe.mesh));
    const Mesh<3> back = parse_msh<3>(msh);
    const Mesh<3>& m = a.r.fe.mesh;
    RC_ASSERT(back.points == m.points);  // bit for bit
    RC_ASSERT(back.solid.type == m.solid.type);
    RC_ASSERT(back.solid.offset == m.solid.offset);
    RC_ASSERT(back.solid.node == m.solid.node);
    RC_ASSERT(back.interface.type == m.interface.type);
    RC_ASSERT(back.interface.offset == m.interface.offset);
    RC_ASSERT(back.interface.node == m.interface.node);
  });
  tally.print("determinism");
}

TEST_CASE("the 3D FE volume approaches the surface's volume as the level rises", "[property][pipeline3d]") {
  Tally tally;
  test::prop("volume error at level 4 below that at level 2", 3, [&] {
    const SurfaceSpec spec = *test::gen_sphere_spec(2);
    std::vector<double> err;
    for (int level = 2; level <= 4; ++level) {
      const Outcome3 out = run_case(spec, level, tally);
      RC_ASSERT(out.v.valid);
      err.push_back(std::abs(out.fe_volume - out.surface_volume) / out.surface_volume);
    }
    RC_LOG() << "volume errors " << err[0] << " " << err[1] << " " << err[2] << "\n";
    RC_ASSERT(err[2] < err[0]);
  });
  tally.print("volume convergence");
}

// ---- survey: how many cases of a family fail, without stopping at the first (hidden) ----

namespace {

/// The fallbacks that made a mesh (Result3d's flags, report.json's names), comma-separated.
std::string fallbacks_of(const Result3d& r) {
  std::string out;
  const std::pair<bool, const char*> flags[] = {{r.buffer_dropped, "buffer_rule_dropped"},
                                                {r.buffer_fallback, "buffer_rule_fallback"},
                                                {r.features_dropped, "feature_snapping_dropped"},
                                                {r.facing_projection, "facing_projection"},
                                                {r.thickness_refined, "thickness_refined"},
                                                {r.thickness_after_refusal, "thickness_after_refusal"},
                                                {r.thickness_early, "thickness_early"},
                                                {r.thin_parts_coarse, "thin_parts_coarse"},
                                                {r.level_raised > 0, "level_raised"},
                                                {r.frame.turned, "planar_frame"},
                                                {r.frame_refused, "frame_refused"},
                                                {r.lattice_draw > 0, "lattice_draw"},
                                                {r.lattice_draws_run > 0, "lattice_draws_run"},
                                                {r.flat_retry_made && !r.flat_retry, "flat_retry_not_kept"},
                                                {r.flat_retry, "flat_retry"}};
  for (const auto& [set, name] : flags)
    if (set) out += (out.empty() ? "" : ",") + std::string(name);
  return out;
}

}  // namespace

// FEBEMESH_SURVEY=sphere1|torus|voxel FEBEMESH_SURVEY_CASES=N [FEBEMESH_SURVEY_DIR=DIR]
// [FEBEMESH_SURVEY_KEEP=FLAG] [FEBEMESH_SURVEY_GIVEN_AXES=1] [FEBEMESH_SURVEY_LATTICE_DRAWS=N]
// [RC_PARAMS="seed=S"] test_dim3 "[.survey]" (GIVEN_AXES: Options3d::align_planar_faces off;
// LATTICE_DRAWS: Options3d::lattice_draws, 0 for one lattice; FEBEMESH_SURVEY_DRAW_BELOW=DEG:
// Options3d::draw_min_dihedral_deg; FEBEMESH_SURVEY_DRAW_LOST=PCT: draw_max_volume_error in
// percent; FEBEMESH_SURVEY_FLAT_RETRY=DEG: flat_retry_below_deg): runs N generated cases
// of the family (the same generators and sizes as the properties above), prints every case with
// the fallbacks that made its mesh, every refused or invalid one with why and, with
// FEBEMESH_SURVEY_DIR, writes those there as OFF files (unshrunk), and the valid ones whose
// fallbacks include FEBEMESH_SURVEY_KEEP (e.g. thickness_early). Never fails: it measures.
TEST_CASE("3D pipeline survey of a property family", "[.survey]") {
  const char* kind = std::getenv("FEBEMESH_SURVEY");
  if (!kind) return;
  const std::string k = kind;
  const rc::Gen<SurfaceSpec> gen = k == "torus"   ? test::gen_torus_spec()
                                  : k == "voxel"  ? test::gen_voxel_spec()
                                  : k == "sphere2" ? test::gen_sphere_spec(2)
                                                   : test::gen_sphere_spec(1);
  const char* cases_env = std::getenv("FEBEMESH_SURVEY_CASES");
  const char* dir = std::getenv("FEBEMESH_SURVEY_DIR");
  const char* keep = std::getenv("FEBEMESH_SURVEY_KEEP");
  const bool given_axes = std::getenv("FEBEMESH_SURVEY_GIVEN_AXES") != nullptr;
  const char* draws_env = std::getenv("FEBEMESH_SURVEY_LATTICE_DRAWS");
  const int lattice_draws = draws_env ? std::atoi(draws_env) : Options3d{}.lattice_draws;
  const char* below_env = std::getenv("FEBEMESH_SURVEY_DRAW_BELOW");
  const double draw_below = below_env ? std::atof(below_env) : Options3d{}.draw_min_dihedral_deg;
  const char* lost_env = std::getenv("FEBEMESH_SURVEY_DRAW_LOST");
  const double draw_lost = lost_env ? std::atof(lost_env) / 100 : Options3d{}.draw_max_volume_error;
  const char* flat_env = std::getenv("FEBEMESH_SURVEY_FLAT_RETRY");
  const double flat_retry = flat_env ? std::atof(flat_env) : Options3d{}.flat_retry_below_deg;
  rc::detail::TestParams params = rc::detail::configuration().testParams;
  params.maxSuccess = cases_env ? std::atoi(cases_env) : 20;
  params.disableShrinking = true;
  Tally tally;
  long n = 0, failed = 0;
  rc::detail::TestMetadata metadata;
  metadata.id = metadata.description = "survey " + k;
  rc::detail::checkTestable(
      [&] {
        const SurfaceSpec spec = *gen;
        const long index = n++;
        std::string why, how;
        double lost = -1.0;
        const auto t0 = std::chrono::steady_clock::now();
        try {
          const Outcome3 out = run_surface(test::to_surface(spec), spec.level, given_axes, lattice_draws, draw_below, draw_lost, flat_retry);
          ++tally.cases;
          how = fallbacks_of(out.r);
          lost = std::abs(out.fe_volume - out.surface_volume) / std::abs(out.surface_volume);
          if (!out.v.valid) why = "INVALID: " + out.v.summary();
          else if (std::abs(out.fe_volume - out.be_volume) > out.round_off) why = "volume gap";
        } catch (const GeometryError& e) {
          why = std::string("GeometryError: ") + e.what();
        } catch (const LimitError& e) {
          why = std::string("LimitError: ") + e.what();
        }
        const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::printf("[survey] case %ld %s %.1f s, %.2f%% lost%s\n", index, why.empty() ? "ok" : "FAILED", sec, 100 * lost,
                    how.empty() ? "" : (" (" + how + ")").c_str());
        if (why.empty() && dir && keep && ("," + how + ",").find("," + std::string(keep) + ",") != std::string::npos)
          std::ofstream(fs::path(dir) / (k + "-" + std::to_string(index) + ".off")) << test::to_off(spec);
        if (!why.empty()) {
          ++failed;
          std::printf("[survey] case %ld FAILED: %s\n  %s\n", index, test::describe(spec).c_str(), why.c_str());
          if (dir) {
            std::ofstream(fs::path(dir) / (k + "-" + std::to_string(index) + ".off")) << test::to_off(spec);
          }
        }
        std::fflush(stdout);
      },
      metadata, params);
  std::printf("[survey] %s: %ld cases, %ld failed\n", k.c_str(), n, failed);
}

// ---- shrunk counterexamples (tests/dim3/regressions/*.off), in the unit suite ----
// Found in their given axes: the tests of one mechanism below mesh them so (most are voxel
// unions at an angle, which mesh3d now meshes in the frame of their faces,
// Options3d::align_planar_faces); the whole folder meshes with the defaults.

namespace {

/// Files of the regressions folder; "mayfail-" ones record failures not fixed yet.
std::vector<fs::path> regression_files(bool mayfail) {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(FEBEMESH_SOURCE_DIR) / "tests" / "dim3" / "regressions";
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".off" && (e.path().filename().string().rfind("mayfail-", 0) == 0) == mayfail)
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

/// The level from the "# level N" comment the generator writes (to_off).
int file_level(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("# level ", 0) == 0) return std::stoi(line.substr(8));
  return 3;
}

int n_reports_handed_on = 0;  // by check_regression's meshes

void check_regression(const fs::path& file) {
  INFO(file.string());
  std::ifstream in(file);
  Surface surface(read_off(in, file.string()));
  std::string refused;
  try {
    const Outcome3 out = run_surface(std::move(surface), file_level(file));
    INFO(out.v.summary());
    CHECK(out.v.valid);
    CHECK(out.max_node_distance <= out.tolerance);
    CHECK(std::abs(out.fe_volume - out.be_volume) <= out.round_off);
    // A report the pipeline hands on (the CLI then does not validate again) is the validator's
    // report of this very mesh.
    if (out.r.validation) {
      CHECK(out.r.validation_hash == content_hash(out.r.fe.mesh));
      CHECK(out.r.validation->summary() == out.v.summary());
      ++n_reports_handed_on;
    }
  } catch (const GeometryError& e) {
    refused = e.what();
  } catch (const LimitError& e) {
    refused = e.what();
  }
  INFO(refused);
  CHECK(refused.empty());
}

}  // namespace

TEST_CASE("shrunk 3D property counterexamples mesh validly", "[pipeline3d][regression]") {
  // Under the sanitizers the ones that take 6-16 s CPU in Release (CLI, one thread: torus-seed12
  // 15.6, voxel-hanging-node 12.0, voxel-island-trial 9.6, voxel-seed4-case81 6.6) are left to
  // the Release suite: with them the sanitizer suite's dim3 test took 609 s instead of about 200.
  const std::set<std::string> slow = {"torus-seed12-case195-euler.off", "voxel-hanging-node-concave-edge.off",
                                      "voxel-island-trial.off", "voxel-seed4-case81-buffer-fallback.off"};
  const std::string raised = "voxel-seed5-case180-level-raised.off";  // its own test below
  n_reports_handed_on = 0;
  for (const fs::path& f : regression_files(false))
    if (f.filename() != raised && !(test::sanitized() && slow.count(f.filename().string()))) check_regression(f);
  WARN("meshes that came with the pipeline's validation report: " << n_reports_handed_on);
}

TEST_CASE("a fin of a boundary octant is cancelled rather than refined around", "[pipeline3d][regression]") {
  // The notched cube (7 of 8 cells) at level 3: a face corner's two neighbours project near the
  // notch's concave corner and the corner itself elsewhere, so two side triangles of the octant
  // lie back to back; their cones had opposite volumes, one inverted, and every repair failed.
  const fs::path file = fs::path(FEBEMESH_SOURCE_DIR) / "tests" / "dim3" / "regressions" / "voxel-notched-cube-fin.off";
  std::ifstream in(file);
  const Outcome3 out = run_surface(Surface(read_off(in, file.string())), file_level(file), true);  // its axes
  INFO(out.v.summary());
  CHECK(out.v.valid);
  CHECK(out.r.fe.n_fins_cancelled > 0);
  CHECK(out.r.n_repairs == 0);
}

TEST_CASE("a tree with the wrong Euler characteristic is refined before the quality stage", "[pipeline3d][regression]") {
  // Seed 12's 24x14 torus at level 3 loses its handle on its first tree (Euler 1, expected 0).
  // The quality stage keeps the topology, so the surface refinement is decided before it and
  // the stage runs once, on the finer tree (it ran on both before session 27).
  const fs::path file = fs::path(FEBEMESH_SOURCE_DIR) / "tests" / "dim3" / "regressions" / "torus-seed12-case195-euler.off";
  std::ifstream in(file);
  const Outcome3 out = run_surface(Surface(read_off(in, file.string())), file_level(file), true);  // its axes
  INFO(out.v.summary());
  CHECK(out.v.valid);
  CHECK(out.r.n_repairs >= 1);
  const auto smoothing_runs = std::count_if(out.r.times.begin(), out.r.times.end(),
                                            [](const StageTime3& t) { return t.name == "smoothing"; });
  CHECK(smoothing_runs == 1);
}

TEST_CASE("a cheap refusal at a coarse level is meshed one level finer", "[pipeline3d][regression]") {
  // The 4x4x4 voxel union of seed 5, case 180 at level 3: every try is refused (inverted
  // tetrahedra at its concave edges, two octants apart), after about 0.3M octants built;
  // Options3d::raise_levels meshes it at level 4 (measured: 68248 tets, 4.77 deg, 5.7% volume
  // lost at its one-voxel parts, 15.7 s CPU in Release). Without the raise it is refused.
  if (test::sanitized()) return;  // too slow under ASan; the Release suite runs it
  const fs::path file = fs::path(FEBEMESH_SOURCE_DIR) / "tests" / "dim3" / "regressions" / "voxel-seed5-case180-level-raised.off";
  REQUIRE(file_level(file) == 3);
  std::ifstream in(file);
  const Surface surface(read_off(in, file.string()));
  const Outcome3 out = run_surface(surface, 3, true, 0);  // its axes, one lattice
  INFO(out.v.summary());
  CHECK(out.v.valid);
  CHECK(out.r.level_raised == 1);
  CHECK(out.r.lattice_draws_run == 0);
  // With the lattice draws (Options3d::lattice_draws) the draws at level 3 come first, and the
  // raise only when none of them stands undegraded (a raised mesh is degraded): the second
  // draw stands, and no tree of level 4 is built (it was, before the draws, until session 42).
  const auto said_at = [](const std::vector<std::string>& said, const std::string& what) {
    return std::find_if(said.begin(), said.end(), [&](const std::string& m) { return m.find(what) != std::string::npos; }) -
           said.begin();
  };
  const std::string finer = "once more at level 4";
  std::vector<std::string> said;
  const Outcome3 drawn = run_surface(surface, 3, true, Options3d{}.lattice_draws, Options3d{}.draw_min_dihedral_deg,
                                     Options3d{}.draw_max_volume_error, Options3d{}.flat_retry_below_deg, 0.0, &said);
  INFO(drawn.v.summary());
  CHECK(drawn.v.valid);
  CHECK(drawn.r.level_raised == 0);
  CHECK(drawn.r.lattice_draw > 0);
  CHECK(drawn.r.lattice_draws_run == drawn.r.lattice_draw);
  CHECK(summarize_quality<3>(drawn.r.fe.mesh).min_angle_deg >= Options3d{}.draw_min_dihedral_deg);
  CHECK(said_at(said, finer) == static_cast<std::ptrdiff_t>(said.size()));
  // One draw only: it is degraded too (a part left out), so the raise comes after it, and of the
  // three runs the raised one, which loses the least, stands.
  said.clear();
  const Outcome3 one_draw = run_surface(surface, 3, true, 1, Options3d{}.draw_min_dihedral_deg,
                                        Options3d{}.draw_max_volume_error, Options3d{}.flat_retry_below_deg, 0.0, &said);
  INFO(one_draw.v.summary());
  CHECK(one_draw.v.valid);
  CHECK(one_draw.r.level_raised == 1);
  CHECK(one_draw.r.lattice_draw == 0);
  CHECK(one_draw.r.lattice_draws_run == 1);
  const auto shifted = said_at(said, "with the lattice shifted");
  CHECK(shifted < static_cast<std::ptrdiff_t>(said.size()));
  CHECK(shifted < said_at(said, finer));
  CHECK(said_at(said, finer) < static_cast<std::ptrdiff_t>(said.size()));
}

TEST_CASE("shrunk 3D property counterexamples not fixed yet", "[pipeline3d][regression][!mayfail]") {
  // Not under the sanitizers: these are refused through every try (17 CPU s in Release, several
  // minutes under ASan) and cannot fail the run; the refusal paths run in other tests.
  if (test::sanitized()) return;
  for (const fs::path& f : regression_files(true)) check_regression(f);
}
