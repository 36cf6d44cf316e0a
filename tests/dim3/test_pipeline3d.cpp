// The 3D pipeline on real data: sphere966.off at level 4 gives a valid mesh (positive,
// conforming, interface = boundary faces on the surface, V - E + F - C = 1) whose volume is
// within a few percent of the surface's; `febemesh mesh3d` refuses an open surface.

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/local_repair.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface_checks.hpp"
#include "dim3/tet_optimize.hpp"
#include "scratch_dir.hpp"
#include "thrown.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

/// The boundary of a closed triangle soup (validated as `name`).
SurfaceBoundary boundary_of(const TriangleSoup& soup, const std::string& name) {
  Surface surface(soup);
  validate_surface(surface, name);
  return SurfaceBoundary(std::move(surface));
}

/// The boundary octants of the interior octants `in` with `bo`, tetrahedralized as the templates
/// make them before any untangling: how many tetrahedra are inverted or flat. `stats` receives
/// the construction's counts.
std::size_t raw_inverted_tets(const Orthtree<3>& tree, const Flags& in, const SurfaceBoundary& s,
                              const BoundaryOctantOptions& bo, BoundaryOctantStats& stats) {
  const OctantComplexResult oc = build_octant_complex(tree, in, s, bo);
  REQUIRE(oc.problems.empty());
  stats = oc.stats;
  const SurfacePointFn sp = [&](const P3& p) {
    const ClosestPoint<3> cp = s.closest_point(p);
    return std::make_pair(P3(cp.point), cp.where);
  };
  const TetMesh fe = tetrahedralize(tree, oc.complex, sp);
  std::size_t n = 0;
  for (std::size_t e = 0; e < fe.mesh.solid.size(); ++e) {
    const VertexId* v = fe.mesh.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const P3 &a = fe.mesh.points[v[0].v], &b = fe.mesh.points[v[1].v], &c = fe.mesh.points[v[2].v],
             &d = fe.mesh.points[v[3].v];
    n += (b - a).dot((c - a).cross(d - a)) > 0 ? 0 : 1;
  }
  return n;
}

/// The options of a regression file's case: `level`, one thread, the file's own axes and one
/// lattice: the regressions were found in them, and most are voxel unions at an angle, which
/// mesh3d would mesh in the frame of their faces (Options3d::align_planar_faces); these tests
/// are of the tries on one lattice, not of the lattice draws (Options3d::lattice_draws).
Options3d in_own_axes(int level) {
  Options3d opt;
  opt.level = level;
  opt.n_threads = 1;
  opt.align_planar_faces = false;
  opt.lattice_draws = 0;
  return opt;
}

/// mesh3d of `s` at `level` in its own axes (in_own_axes) with Options3d::thickness_probe on or
/// off, its progress lines into `lines`; checks that the mesh is valid and stood at the probe
/// exactly when the probe is on.
Result3d probe_run(SurfaceBoundary& s, int level, bool probe, std::vector<std::string>& lines) {
  Options3d opt = in_own_axes(level);
  opt.thickness_probe = probe;
  Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO("probe " << probe << ": " << v.summary());
  CHECK(v.valid);
  CHECK(r.thickness_early == probe);
  return r;
}

}  // namespace

TEST_CASE("sphere966 at level 4 gives a valid mesh close to the sphere's volume", "[pipeline3d]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.level = 4;
  const Result3d r = mesh3d(s, opt);
  const Mesh<3>& m = r.fe.mesh;
  REQUIRE(m.solid.size() > 0);
  REQUIRE(m.interface.size() > 0);

  ValidateOptions<3> vo;
  vo.expected_euler = s.euler_characteristic() / 2;
  vo.boundary_distance = [&](const Point<3>& p) { return s.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * s.bounding_box().extent().norm();
  const ValidationReport v = validate(m, vo);
  INFO(v.summary());
  CHECK(v.valid);

  const Fidelity3d f = measure_fidelity(m, s, 2);
  CHECK(f.volume_rel_error < 0.03);
  CHECK(f.max_node_distance <= vo.boundary_tolerance);
  CHECK(f.hausdorff_rel < 0.05);
  const QualitySummary q = summarize_quality(m);
  CHECK(q.min_angle_deg > 0.0);
}

TEST_CASE("mesh3d refuses an open surface with exit 1 and writes nothing", "[pipeline3d][cli]") {
  const test::ScratchDir scratch("test_open_cylinder");
  const std::filesystem::path out = scratch.path() / "out";
  const std::string cmd = std::string(FEBEMESH_CLI) + " mesh3d " + FEBEMESH_DATA_DIR + "/3d/open-cylinder.off -o " +
                          out.string() + " --quiet 2> " + out.string() + ".err";
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK_FALSE(std::filesystem::exists(out));
}

// A torus whose tube (0.7 across) is 1.1 octants thick at --size 1.745 level-3 octants
// (test_dim3 "[property]" seed 1159): no octant lies inside it, so every try built an empty mesh,
// whose Euler characteristic 0 is the torus's, and the run stood on it, "valid", with 0
// tetrahedra. Now an empty mesh has the wrong topology (the octants on the surface are refined,
// as for a sphere that falls apart) and no try stands on one.
TEST_CASE("mesh3d: a torus thinner than the octants is meshed, not left empty", "[pipeline3d]") {
  SurfaceBoundary s =
      SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/torus-seed1159-size-empty.off");
  Options3d opt;
  opt.level = 3;
  opt.size = 1.745 * s.root_box().extent()[0] / 8.0;
  const Result3d r = mesh3d(s, opt);
  REQUIRE(r.fe.mesh.solid.size() > 0);
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(r.fe.mesh.interface.size() > 0);
  CHECK(r.level_raised == 0);
  // The first tree has no interior octant: a run on it alone (no topology refinement, no
  // thin-part retry, no draws) is refused, naming it.
  Options3d bare = opt;
  bare.topology_refinements = 0;
  bare.thin_retry_cells = 0.0;
  bare.lattice_draws = 0;
  bare.raise_levels = 0;
  bare.coarse_thin_after_refusal = false;
  bare.refused_thickness_cells = 0.0;
  bare.align_planar_faces = false;
  const std::string what = test::thrown_message<GeometryError>([&] { mesh3d(s, bare); });
  CHECK(what.find("no interior octant") != std::string::npos);
}

// The work bound (Options3d::effort): the coarse perturbed sphere of the regressions, with
// feature snapping forced, needs 3 repairs, then meshes without it (3088 + 5461 + 8856 + 11775
// + 3088 = 32268 octants built on, measured). A bound of twice the first tree (6176) stops it
// at the first repair's tree, where no valid mesh is at hand: LimitError, naming the bound.
TEST_CASE("the work bound stops the repairs of mesh3d with LimitError", "[pipeline3d]") {
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/sphere-coarse-inverted-element.off";
  Options3d opt;
  opt.level = 3;
  opt.n_threads = 1;
  opt.min_effort_octants = 0;
  opt.faceted_free_ends = 1.0;  // snap although its creases are facets (see the next test)
  // The order of tries this bound was measured on: the buffer rule's try first, each try once
  // more without snapping at once (with the tries without snapping last, the run keeps snapping
  // and drops the buffer rule).
  opt.features_fallback_last = false;
  opt.buffer_last = false;
  if (!test::sanitized()) {  // the whole run: 5 CPU s in Release, too long under ASan
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    const Result3d r = mesh3d(s, opt);
    CHECK(r.features_dropped);
    CHECK(r.n_octants_built > 3 * r.n_leaves_subdivided);
    CHECK(r.n_octants_built <= static_cast<std::size_t>(opt.effort * static_cast<double>(r.n_leaves_subdivided)));
    CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
  }
  opt.effort = 2.0;
  SurfaceBoundary s = SurfaceBoundary::from_file(file);
  const std::string what = test::thrown_message<LimitError>([&] { mesh3d(s, opt); });
  INFO(what);
  CHECK(what.find("over its work bound of 6176") != std::string::npos);
}

// Options3d::refused_thickness_cells: a refused run has one more try with the thickness level
// when part of the solid is thinner than that many octants of level + 1, and when that is refused
// too the error is the first one's type, with both reasons. A plate 0.05 thick at level 3
// (level-4 octants 0.066): a work bound under the first tree refuses every try at once.
TEST_CASE("mesh3d tries the thickness level once after a refusal of a thin part", "[pipeline3d][thickness]") {
  const double h = 0.05;
  TriangleSoup soup;
  soup.vertices = {P3(0, 0, 0), P3(1, 0, 0), P3(1, 1, 0), P3(0, 1, 0),
                   P3(0, 0, h), P3(1, 0, h), P3(1, 1, h), P3(0, 1, h)};
  soup.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                    {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  const auto refusal = [&](double cells) {
    SurfaceBoundary s = boundary_of(soup, "plate");
    Options3d opt;
    opt.level = 3;
    opt.effort = 0.5;
    opt.min_effort_octants = 0;
    opt.raise_levels = 0;
    opt.refused_thickness_cells = cells;
    return test::thrown_message<LimitError>([&] { mesh3d(s, opt); });
  };
  const std::string with = refusal(4.0), without = refusal(0.0);
  INFO(with);
  CHECK(with.find("over its work bound") != std::string::npos);
  CHECK(with.find("octants across the thin parts: the boundary octants could not be built within the work bound") !=
        std::string::npos);
  CHECK(with.find("; with 4 octants across the thin parts: ") != std::string::npos);  // not "4.000000"
  CHECK(with.find("; without the feature level: ") != std::string::npos);  // coarse_thin_after_refusal
  INFO(without);
  CHECK(without.find("over its work bound") != std::string::npos);
  CHECK(without.find("octants across the thin parts") == std::string::npos);
  // Thicker than 0.1 octant of level 4 everywhere (a cube): no second try.
  soup.vertices = {P3(0, 0, 0), P3(1, 0, 0), P3(1, 1, 0), P3(0, 1, 0),
                   P3(0, 0, 1), P3(1, 0, 1), P3(1, 1, 1), P3(0, 1, 1)};
  CHECK(refusal(0.1).find("octants across the thin parts") == std::string::npos);
}

// Options3d::coarse_thin_after_refusal: when the thickness try is refused too, one more try
// without the feature level and the thin parts' refinements, which leaves out parts thinner than
// the octants. A block with a fin 0.02 thick (rotor's blades) at level 4: every triangle touches
// a feature edge, so the feature level refines the whole surface to level 5 and the thickness
// level refines the fin further; a cap on the tree's leaves between those trees and the uniform
// level-4 one refuses the tries that refine, and the coarse try meshes the block without the fin.
TEST_CASE("mesh3d leaves out the thin parts after every refining try is refused", "[pipeline3d][thickness]") {
  // The profile in the xz plane (a square with a thin fin on its right side), extruded along y.
  const std::array<std::array<double, 2>, 8> xz{{{0, 0}, {0.6, 0}, {0.6, 0.29}, {1, 0.29}, {1, 0.31}, {0.6, 0.31},
                                                 {0.6, 0.6}, {0, 0.6}}};
  TriangleSoup soup;
  for (double y : {0.0, 0.6})
    for (const auto& p : xz) soup.vertices.push_back(P3(p[0], y, p[1]));
  // The profile's triangles (counter-clockwise in x, z), at y = 0.6 (their normal +y) and at y = 0
  // reversed; the sides between.
  const std::array<std::array<int, 3>, 6> cap{{{0, 1, 2}, {0, 2, 5}, {0, 5, 6}, {0, 6, 7}, {2, 3, 4}, {2, 4, 5}}};
  for (const auto& t : cap) {
    soup.triangles.push_back({t[0], t[2], t[1]});
    soup.triangles.push_back({8 + t[0], 8 + t[1], 8 + t[2]});
  }
  for (int i = 0; i < 8; ++i) {
    const int j = (i + 1) % 8;
    soup.triangles.push_back({i, j, 8 + j});
    soup.triangles.push_back({i, 8 + j, 8 + i});
  }
  const auto run = [&](bool coarse, Result3d& r) {
    SurfaceBoundary s = boundary_of(soup, "block with a fin");
    Options3d opt;
    opt.level = 4;
    opt.n_threads = 1;
    opt.raise_levels = 0;
    opt.max_cells = 3 * 4096;  // the uniform level-4 tree has 8^4 leaves
    opt.coarse_thin_after_refusal = coarse;
    std::string what;
    try {
      r = mesh3d(s, opt);
      const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
      INFO(v.summary());
      CHECK(v.valid);
      const double fin = 0.4 * 0.02 * 0.6, block = 0.6 * 0.6 * 0.6;
      // The block, without the fin (at level 4 its edges are cut a little: 0.2076 of 0.216).
      const double v_mesh = solid_measure<3>(r.fe.mesh);
      CHECK(v_mesh > 0.95 * block);
      CHECK(v_mesh < block + 0.5 * fin);
      CHECK(s.volume() == Approx(block + fin));
    } catch (const LimitError& e) {
      what = e.what();
    }
    return what;
  };
  Result3d with, without;
  const std::string refused = run(false, without);
  INFO(refused);
  CHECK(refused.find("octants across the thin parts") != std::string::npos);
  CHECK(run(true, with).empty());
  CHECK(with.thin_parts_coarse);
  CHECK_FALSE(with.thickness_after_refusal);
}

namespace {

/// The fallbacks mesh3d announced, in order: each progress message "X, after: why" gives X.
struct Fallbacks {
  std::vector<std::string> seen;
  Progress3 progress() {
    return [this](const std::string& m) {
      const auto at = m.find(", after: ");
      if (at != std::string::npos) seen.push_back(m.substr(0, at));
    };
  }
};

}  // namespace

// Options3d::features_fallback_last on the 12x8 torus of the regressions (every edge a feature,
// no free ends, so snapped to): with feature snapping and the buffer rule it is refused. Off, the
// next try drops the snapping; on, it drops the buffer rule and keeps the snapping, and meshes.
// (The order with the buffer rule's try first, Options3d::buffer_last off; on, the try without
// the buffer rule and with snapping is the first and stands, below.)
TEST_CASE("mesh3d with features_fallback_last tries feature snapping without the buffer next", "[pipeline3d]") {
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/torus-12x8-feature-snap-inverted.off";
  Options3d opt;
  opt.level = 3;
  opt.n_threads = 1;
  opt.thin_retry_cells = 0;  // the flags of the first mesh, not of the thickness retry's
  opt.buffer_last = false;
  for (const bool last : {false, true}) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    REQUIRE_FALSE(s.features().free_end_share() > opt.faceted_free_ends);
    opt.features_fallback_last = last;
    Fallbacks f;
    const Result3d r = mesh3d(s, opt, f.progress());
    INFO("features_fallback_last " << last);
    REQUIRE_FALSE(f.seen.empty());
    CHECK(f.seen[0] == (last ? "without the buffer rule" : "without feature snapping"));
    CHECK(r.features_dropped == !last);
    CHECK(r.buffer_dropped == last);
    CHECK_FALSE(r.facing_projection);
    CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
  }
}

// On the voxel union of the regressions with a hanging node at a concave edge (its cube edges
// are features, with no free ends) at level 3 with one repair a try, every try that snaps is
// refused, and the one without snapping and with the buffer rule too: features_fallback_last
// runs them in mesh3d's order, the three with snapping first, and the mesh is the one without
// snapping and without the buffer rule; the flags say so.
TEST_CASE("mesh3d with features_fallback_last drops feature snapping after every try with it", "[pipeline3d]") {
  if (test::sanitized()) return;  // 3 CPU s in Release (five tries of up to two trees)
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-hanging-node-concave-edge.off";
  SurfaceBoundary s = SurfaceBoundary::from_file(file);
  Options3d opt = in_own_axes(3);
  opt.max_repairs = 1;
  opt.raise_levels = 0;
  opt.thin_retry_cells = 0;
  opt.features_fallback_last = true;
  opt.buffer_last = false;  // the buffer rule's try first (the order this case was found in)
  REQUIRE_FALSE(s.features().free_end_share() > opt.faceted_free_ends);
  Fallbacks f;
  const Result3d r = mesh3d(s, opt, f.progress());
  const std::vector<std::string> order = {"without the buffer rule", "with facing projections only",
                                          "without feature snapping, every try", "without the buffer rule"};
  CHECK(f.seen == order);
  CHECK(r.features_dropped);
  CHECK(r.buffer_dropped);
  CHECK_FALSE(r.facing_projection);
  CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
}

// Options3d::buffer_last (the default): the try without the buffer rule first, then the one
// with facing projections, then the buffer rule's. The 12x8 torus above meshes at the first
// try, with snapping and without the buffer rule (where the buffer rule's try was refused
// first); on the voxel union with the hanging node all three tries with snapping are refused in
// that order, and the mesh is the first try without snapping, without the buffer rule.
TEST_CASE("mesh3d tries without the buffer rule first, with facing projections next, the buffer rule last", "[pipeline3d]") {
  Options3d opt = in_own_axes(3);
  opt.thin_retry_cells = 0;
  REQUIRE(opt.buffer_last);
  REQUIRE(opt.buffer > 0);
  {
    SurfaceBoundary s =
        SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/torus-12x8-feature-snap-inverted.off");
    Fallbacks f;
    const Result3d r = mesh3d(s, opt, f.progress());
    CHECK(f.seen.empty());
    CHECK_FALSE(r.features_dropped);
    CHECK_FALSE(r.buffer_dropped);
    CHECK_FALSE(r.buffer_fallback);
    CHECK_FALSE(r.facing_projection);
    CHECK(r.n_buffer_dropped == 0);  // no buffer rule in the try that stood
    CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
  }
  if (test::sanitized()) return;  // 2 CPU s in Release (four tries)
  SurfaceBoundary s =
      SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-hanging-node-concave-edge.off");
  opt.max_repairs = 1;
  opt.raise_levels = 0;
  Fallbacks f;
  const Result3d r = mesh3d(s, opt, f.progress());
  const std::vector<std::string> order = {"with facing projections only", "with the buffer rule",
                                          "without feature snapping, every try"};
  CHECK(f.seen == order);
  CHECK(r.features_dropped);
  CHECK_FALSE(r.buffer_dropped);
  CHECK_FALSE(r.buffer_fallback);
  CHECK_FALSE(r.facing_projection);
  CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
}

// The buffer rule's try, last, standing where the two before it are refused: voxel union seed 4,
// case 81 of the survey, at level 3 (found in session 31 by counting the tries of 200 cases of
// voxel seeds 4 and 5: it stood once and was refused six times). Without the thickness retry,
// which replaced this mesh (it loses 10.7% of the volume), and without the thickness probe,
// which makes the CLI's mesh since session 32 (59,373 tets, 19.67 deg, 4.91%, 0.84 s CPU,
// instead of the retry's 98,262, 16.37 deg, 7.32%, 5.47 s), so that the try's own mesh and
// flags are seen.
TEST_CASE("mesh3d's buffer rule try stands when the tries without it are refused", "[pipeline3d]") {
  if (test::sanitized()) return;  // about 3 CPU s in Release (three tries)
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_SOURCE_DIR) +
                                                 "/tests/dim3/regressions/voxel-seed4-case81-buffer-fallback.off");
  Options3d opt = in_own_axes(3);
  opt.thin_retry_cells = 0;
  opt.thickness_probe = false;
  Fallbacks f;
  const Result3d r = mesh3d(s, opt, f.progress());
  const std::vector<std::string> order = {"with facing projections only", "with the buffer rule"};
  CHECK(f.seen == order);
  CHECK(r.buffer_fallback);
  CHECK_FALSE(r.buffer_dropped);
  CHECK_FALSE(r.facing_projection);
  CHECK_FALSE(r.features_dropped);
  CHECK(r.n_buffer_dropped > 0);
  CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
}

// Options3d::thickness_probe: voxel union seed 4, case 50 of the survey, at level 3 (found in
// session 32 with FEBEMESH_SURVEY_KEEP=thickness_early). Its first tree has problems at parts one
// voxel thick; the first tree with 4 octants across them has none and stands. Without the probe
// the first try's repairs stand and lose 10.3% of the volume, and the thickness retry keeps its
// mesh (thickness_refined, CLI: 40,415 tets, 17.16 deg, 10.31%, 1.08 s CPU); with it, 55,533
// tets, 19.97 deg, 4.80%, 0.68 s.
TEST_CASE("mesh3d's thickness probe stands where the first tree has problems at thin parts", "[pipeline3d]") {
  const std::string file =
      std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-seed4-case50-thickness-early.off";
  // Under the sanitizers the run with the probe only (without it: 1 CPU s in Release).
  const std::vector<bool> probes = test::sanitized() ? std::vector<bool>{true} : std::vector<bool>{true, false};
  double error[2] = {1.0, 1.0};
  for (const bool probe : probes) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    std::vector<std::string> lines;
    const Result3d r = probe_run(s, 3, probe, lines);
    CHECK(r.thickness_refined == !probe);
    const bool probed = std::any_of(lines.begin(), lines.end(), [](const std::string& m) {
      return m.find("the first tree with the thickness level stands") != std::string::npos;
    });
    CHECK(probed == probe);
    if (probe) {
      // The validator's report comes with the mesh (the CLI does not validate again).
      REQUIRE(r.validation);
      CHECK(r.validation_hash == content_hash(r.fe.mesh));
    }
    error[probe ? 0 : 1] = std::abs(solid_measure<3>(r.fe.mesh) - s.volume()) / s.volume();
  }
  CHECK(error[0] < 0.06);
  if (!test::sanitized()) CHECK(error[0] < error[1]);
}

// After a refusal the thickness try would begin with the thickness probe's tree again: where the
// probe did not stand, it is not tried (rotor L6: 270 s CPU of repairs after the probe's 6%).
// The voxel union with the hanging node at a concave edge at level 3: its first tree has
// problems, the probe's first round of untangling leaves 18 of 744 tetrahedra inverted, and a
// work bound of two first trees refuses every try after it. With the probe the coarse try comes
// next; without it the thickness try runs first (and is refused by its own bound of 2x).
TEST_CASE("mesh3d does not repeat a refused thickness probe's tree after a refusal", "[pipeline3d][thickness]") {
  const std::string file =
      std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-hanging-node-concave-edge.off";
  for (const bool probe : {true, false}) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    Options3d opt = in_own_axes(3);
    opt.effort = 2.0;
    opt.min_effort_octants = 0;
    opt.raise_levels = 0;
    opt.thickness_probe = probe;
    std::vector<std::string> lines;
    const auto said = [&](const std::string& text) {
      return std::count_if(lines.begin(), lines.end(),
                           [&](const std::string& m) { return m.find(text) != std::string::npos; });
    };
    std::string refused;
    try {
      const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
      CHECK(r.thin_parts_coarse);
      CHECK_FALSE(r.thickness_after_refusal);
      CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
    } catch (const LimitError& e) {
      refused = e.what();
    }
    INFO("probe " << probe << ": " << refused);
    CHECK(said("the first tree with the thickness level has problems") == (probe ? 1 : 0));
    CHECK(said("): not once more with 4 octants across the thin parts (its first tree is the thickness probe's: "
               "the first round of untangling left") == (probe ? 1 : 0));
    CHECK(said("): once more with 4 octants across the thin parts") == (probe ? 0 : 1));
    CHECK(said("once more without the feature level") == 1);  // the coarse try, either way
    if (!refused.empty())
      CHECK(refused.find(probe ? "; with 4 octants across the thin parts: its first tree is the thickness probe's"
                               : "; with 4 octants across the thin parts: the boundary octants could not be built") !=
            std::string::npos);
  }
}

// Options3d::thickness_probe at a first tree without an interior octant: a plate 1 x 1 x 0.05 with
// a bore (r 0.2; Gmsh, OpenCASCADE, 390 triangles) at level 4, whose octants (0.066) are thicker
// than it. The thin retry's try (2 octants across, no buffer rule) stands at once. Without the
// probe the tries refine every octant on the surface, level by level, and stand on a finer tree
// (CLI, one thread: 245,292 tets against 157,603, 1.88% of the volume lost either way; a plate
// 2 x 2 x 0.05 lost 55.7% after 19.6 s where the thin parts' try makes 612,398 tets in 1.6 s).
TEST_CASE("mesh3d meshes a solid thinner than the octants everywhere by the thin parts' try at once",
          "[pipeline3d][thickness]") {
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/plate-1x1x0.05-hole.off";
  // Under the sanitizers the run with the probe only.
  const std::vector<bool> probes = test::sanitized() ? std::vector<bool>{true} : std::vector<bool>{true, false};
  std::size_t tets[2] = {0, 0};
  for (const bool probe : probes) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    std::vector<std::string> lines;
    const Result3d r = probe_run(s, 4, probe, lines);
    CHECK(r.level_raised == 0);
    const auto said = [&](const std::string& text) {
      return std::any_of(lines.begin(), lines.end(), [&](const std::string& m) { return m.find(text) != std::string::npos; });
    };
    CHECK(said("no interior octant and the solid is thin: the thin parts' try with 2 octants across") == probe);
    CHECK(said("thin parts: the thin parts' try stands") == probe);
    CHECK(std::abs(solid_measure<3>(r.fe.mesh) - s.volume()) / s.volume() < 0.03);
    tets[probe ? 0 : 1] = r.fe.mesh.solid.size();
  }
  if (!test::sanitized()) CHECK(tets[0] < tets[1]);
}

namespace {

/// A ring (an annulus extruded): radii `outer` > `inner`, height `h`, `n` sides, outward.
TriangleSoup ring_soup(double outer, double inner, double h, int n) {
  TriangleSoup soup;
  for (const double z : {0.0, h})
    for (const double radius : {outer, inner})
      for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * k / n;
        soup.vertices.push_back(P3(radius * std::cos(a), radius * std::sin(a), z));
      }
  const auto at = [&](int top, int in, int k) { return top * 2 * n + in * n + k % n; };
  const auto quad = [&](int a, int b, int c, int d) {
    soup.triangles.push_back({a, b, c});
    soup.triangles.push_back({a, c, d});
  };
  for (int k = 0; k < n; ++k) {
    quad(at(0, 0, k), at(0, 0, k + 1), at(1, 0, k + 1), at(1, 0, k));  // outer wall
    quad(at(0, 1, k), at(1, 1, k), at(1, 1, k + 1), at(0, 1, k + 1));  // inner wall
    quad(at(1, 0, k), at(1, 0, k + 1), at(1, 1, k + 1), at(1, 1, k));  // top
    quad(at(0, 0, k), at(0, 1, k), at(0, 1, k + 1), at(0, 0, k + 1));  // bottom
  }
  return soup;
}

}  // namespace

// The thin parts' try at a first tree without an interior octant, its thickness level's cap
// from the thin parts (SurfaceBoundary::thin_parts_level): a ring r 1, 0.03 thick, 0.06 high at
// level 3. With the cap at level + 2 it was refused at levels 3 and 4 (folds one octant across);
// now (CLI, two threads) valid, 310,522 tets, 28.11 deg, 5.48% of the volume lost, 1.5 s.
TEST_CASE("mesh3d meshes a thin ring whose thin parts need more than two levels", "[pipeline3d][thickness]") {
  if (test::sanitized()) return;  // 310,522 tets: 1.5 s in Release
  SurfaceBoundary s = boundary_of(ring_soup(1.0, 0.97, 0.06, 64), "ring");
  CHECK(s.thin_parts_level(2.0, 3) > 5.0);  // log2(2.1 x 2 / 0.03) = 7.1
  Options3d opt = in_own_axes(3);
  std::vector<std::string> lines;
  const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(r.thickness_early);
  CHECK(r.level_raised == 0);
  CHECK(std::abs(solid_measure<3>(r.fe.mesh) - s.volume()) / s.volume() < 0.06);
  CHECK(std::any_of(lines.begin(), lines.end(),
                    [](const std::string& m) { return m.find("thin parts: the thin parts' try stands") != std::string::npos; }));
}

// Options3d::thin_retry_gap: a cone 2 high, r 0.4 (Gmsh, OpenCASCADE, 230 triangles) at level 5.
// Its first mesh loses 4.17% of the volume, under the thin retry's 5%, but its tip is left out:
// the surface gets 8.3 octants from the BE mesh. The retry for that gap stands (CLI in these
// options, one thread: 16,727 -> 92,868 tets, 1.87 octants, 0.81% of the volume lost).
TEST_CASE("mesh3d retries the thin parts where the surface gets far from the BE mesh", "[pipeline3d][thickness]") {
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/cone-h2-r0.4.off";
  double gap[2] = {0.0, 0.0};
  for (const bool retry : {true, false}) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    Options3d opt = in_own_axes(5);
    if (!retry) opt.thin_retry_gap = 0.0;
    std::vector<std::string> lines;
    const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
    const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
    INFO("retry " << retry << ": " << v.summary());
    CHECK(v.valid);
    CHECK(r.thickness_refined == retry);
    const bool said = std::any_of(lines.begin(), lines.end(), [](const std::string& m) {
      return m.find("octants from the BE mesh: once more with 2 octants across the thin parts") != std::string::npos;
    });
    CHECK(said == retry);
    const double error = std::abs(solid_measure<3>(r.fe.mesh) - s.volume()) / s.volume();
    CHECK(error < opt.thin_retry_error);
    gap[retry ? 0 : 1] = surface_to_be_distance(r.fe.mesh, s) / s.octant_side(opt.level);
  }
  CHECK(gap[0] < 2.0);
  CHECK(gap[1] > 2.0);
}

// Options3d::skip_repeated_rounds on the voxel union of the island trial at level 4: in its first
// try a round of the untangling's surface node moves puts every node back on its own point, and
// the rounds after it are skipped. Off, they run: each prints the skipped round's summary again,
// and every line after it, the refused try's reasons, the mesh (bit for bit) and its counts are
// the same.
TEST_CASE("mesh3d skips the untangling rounds that would repeat one, with the same mesh", "[pipeline3d]") {
  if (test::sanitized()) return;  // 2 x 2.3 CPU s in Release
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-island-trial.off";
  Options3d opt = in_own_axes(4);
  opt.buffer_last = false;  // the skip happens in the buffer rule's try
  std::vector<std::string> lines[2];
  Result3d r[2];
  for (const bool skip : {true, false}) {
    SurfaceBoundary s = SurfaceBoundary::from_file(file);
    opt.skip_repeated_rounds = skip;
    r[skip ? 0 : 1] = mesh3d(s, opt, [&](const std::string& m) { lines[skip ? 0 : 1].push_back(m); });
  }
  // The lines with the skip, each "the N round(s) after this one would repeat it" line replaced
  // by N copies of the untangling line before it: the lines without.
  std::vector<std::string> expanded;
  std::size_t n_skips = 0;
  const std::string mark = "untangling: the ";
  for (const std::string& m : lines[0]) {
    if (m.rfind(mark, 0) == 0 && m.find("would repeat it") != std::string::npos) {
      ++n_skips;
      REQUIRE_FALSE(expanded.empty());
      const std::string repeated = expanded.back();
      CHECK(repeated.rfind("untangling: inverted tetrahedra", 0) == 0);
      const int n = std::stoi(m.substr(mark.size()));
      CHECK(n >= 1);
      for (int k = 0; k < n; ++k) expanded.push_back(repeated);
      continue;
    }
    expanded.push_back(m);
  }
  CHECK(n_skips >= 1);
  CHECK(expanded == lines[1]);
  const Mesh<3>&a = r[0].fe.mesh, &b = r[1].fe.mesh;
  REQUIRE(a.points.size() == b.points.size());
  CHECK(std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(a.points[0])) == 0);
  CHECK(a.solid.node == b.solid.node);
  CHECK(a.interface.node == b.interface.node);
  CHECK(r[0].n_untangled == r[1].n_untangled);
  CHECK(r[0].n_untangle_moves == r[1].n_untangle_moves);
  CHECK(r[0].n_repairs == r[1].n_repairs);
  CHECK(r[0].buffer_dropped == r[1].buffer_dropped);
}

// Options3d::faceted_free_ends: the same sphere's 30-degree creases are facets, most of them
// ending in smooth surface, so mesh3d meshes it without feature snapping at once: one tree, no
// repair, where snapping took 3 repairs and a fallback (above).
TEST_CASE("mesh3d does not snap to the creases of a faceted surface", "[pipeline3d]") {
  const std::string file = std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/sphere-coarse-inverted-element.off";
  SurfaceBoundary s = SurfaceBoundary::from_file(file);
  INFO("free end share " << s.features().free_end_share());
  REQUIRE(s.features().free_end_share() > Options3d{}.faceted_free_ends);
  Options3d opt;
  opt.level = 3;
  opt.n_threads = 1;
  const Result3d r = mesh3d(s, opt);
  CHECK(r.features_dropped);
  CHECK(r.n_octants_built == r.n_leaves_subdivided);
  CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
}

// tet_optimize: a cube split into 12 cones from a centre node; the centre pushed out of the cube
// inverts some cones, the untangling brings it back, and the angle search never lowers the
// minimum dihedral angle.
namespace {

Mesh<3> cube_cones(const P3& centre) {
  Mesh<3> m;
  for (int k = 0; k < 8; ++k) m.add_point(P3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  const VertexId c = m.add_point(centre);
  // Faces as corner quads, counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces)
    for (const auto& t : {std::array<int, 3>{f[0], f[1], f[2]}, std::array<int, 3>{f[0], f[2], f[3]}})
      m.solid.add(ElemType::Tet4, {VertexId{t[0]}, VertexId{t[2]}, VertexId{t[1]}, c});
  return m;
}

std::size_t n_inverted(const Mesh<3>& m) {
  std::size_t n = 0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const auto p = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
    if (signed_measure<3>(ElemType::Tet4, p.span()) <= 0) ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("tet_optimize untangles a displaced centre node and keeps the corners", "[pipeline3d][tet_optimize]") {
  Mesh<3> m = cube_cones(P3(0.5, 0.5, 0.5));
  REQUIRE(n_inverted(m) == 0);
  m = cube_cones(P3(1.4, 0.3, 0.6));
  REQUIRE(n_inverted(m) > 0);
  std::vector<BoundaryLocation> where(m.points.size());
  TetOptimizeOptions to;
  to.untangle_only = true;
  to.fixed.assign(m.points.size(), 0);
  for (int k = 0; k < 8; ++k) to.fixed[k] = 1;
  const TetOptimizeStats st = optimize_tets(m, where, to);
  CHECK(st.inverted_before > 0);
  CHECK(st.inverted_after == 0);
  CHECK(n_inverted(m) == 0);
  for (int k = 0; k < 8; ++k) CHECK(m.points[k] == P3(k & 1, (k >> 1) & 1, (k >> 2) & 1));

  TetOptimizeOptions tq;
  tq.fixed = to.fixed;
  tq.target_dihedral_deg = 60.0;
  const TetOptimizeStats sq = optimize_tets(m, where, tq);
  CHECK(sq.inverted_after == 0);
  CHECK(sq.min_dihedral_after_deg >= sq.min_dihedral_before_deg);
  // The best centre is the cube's centre: every cone then has a 45 degree dihedral angle.
  CHECK(sq.min_dihedral_after_deg > 38.0);
}

// Threads (issue 8): the projections of the boundary octants, the classification, the smoothing
// and the tet optimiser run on opt.n_threads; the mesh and the counts must not depend on it.
// Spool at level 3 without the thickness retry and the thickness probe: the first tree's
// projections include next local minima (22 of them, diagnose3d; the retry's tree had 4 while
// the thickness was measured at the centroids only, none since it is the thinnest of centroid and
// vertices). With the probe (the default), whose tree stands there, as well.
TEST_CASE("mesh3d gives the same mesh and counts on 1 and 2 threads", "[pipeline3d][threads]") {
  for (const bool probe : {false, true}) {
    INFO("thickness probe " << probe);
    SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/spool.off");
    Options3d opt;
    opt.level = 3;
    opt.thin_retry_cells = 0;
    opt.thickness_probe = probe;
    opt.lattice_draws = 0;  // one lattice: its thin flanges lost (over 10%) would draw twice more
    opt.n_threads = 1;
    const Result3d one = mesh3d(s, opt);
    opt.n_threads = 2;
    const Result3d two = mesh3d(s, opt);
    REQUIRE(one.fe.mesh.solid.size() > 10000);
    CHECK(one.thickness_early == probe);
    CHECK(two.thickness_early == probe);
    if (!probe) CHECK(one.stats.n_next_normal > 0);
    CHECK(one.fe.mesh.points == two.fe.mesh.points);  // bit for bit
    CHECK(one.fe.mesh.solid.node == two.fe.mesh.solid.node);
    CHECK(one.fe.mesh.interface.node == two.fe.mesh.interface.node);
    CHECK(one.stats.n_surface_nodes == two.stats.n_surface_nodes);
    CHECK(one.stats.n_shared_projections == two.stats.n_shared_projections);
    CHECK(one.stats.n_next_normal == two.stats.n_next_normal);
    CHECK(one.stats.n_ray == two.stats.n_ray);
    CHECK(one.stats.n_blind == two.stats.n_blind);
    CHECK(one.n_optimize_moves == two.n_optimize_moves);
  }
}

// Backward projections (issue 6, BoundaryOctantOptions::unfold_backward, off by default): a
// face node's closest point that runs back against one of its free faces folds that face's
// boundary octant. On the first tree of regressions/voxel-seed5-case180-level-raised.off at
// level 3 (diagnose3d, no feature snapping) the rule moves 49 surface nodes and the raw
// inverted tetrahedra of the templates go 196 -> 114; it must move some, and leave fewer.
TEST_CASE("unfolding backward projections leaves fewer raw inverted tetrahedra", "[pipeline3d][boundary_octants]") {
  const std::string file =
      std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim3/regressions/voxel-seed5-case180-level-raised.off";
  SurfaceBoundary s = SurfaceBoundary::from_file(file);
  s.set_global_level(3);
  s.set_max_level(5);
  RefineOptions ro;
  ro.max_level = 7;
  const ControlFn<3> control = [&](const Box<3>& b) { return s.control_level(b); };
  const Orthtree<3> tree = balance_2to1(subdivide_by_control(s.root_box(), control, ro), BalanceKind::Full);
  Flags in = interior_flags(classify(tree, s));
  {
    // The whole-face buffer (Options3d::flat_buffer): only octants with a free face near the
    // surface at all its corners and its centre, so fewer than the buffer rule at the same
    // fraction; the same on threads, and nothing more to drop once it is done.
    Flags flat = in, flat3 = in, any = in;
    const std::size_t n_flat = apply_buffer(tree, flat, s, 0.6, 1, true);
    CHECK(n_flat > 0);
    CHECK(n_flat < apply_buffer(tree, any, s, 0.6));
    CHECK(apply_buffer(tree, flat3, s, 0.6, 3, true) == n_flat);
    CHECK(flat3 == flat);
    CHECK(apply_buffer(tree, flat, s, 0.6, 1, true) == 0);
  }
  {
    // The buffer rule's distances on threads: the same octants dropped.
    Flags in3 = in;
    const std::size_t dropped = apply_buffer(tree, in, s, 0.2);
    CHECK(dropped > 0);
    CHECK(apply_buffer(tree, in3, s, 0.2, 3) == dropped);
    CHECK(in3 == in);
  }
  remove_pinches(tree, in);
  keep_largest_components(tree, in, s.n_components());
  BoundaryOctantOptions bo;
  bo.snap_features = false;
  BoundaryOctantStats stats_off, stats_on;
  const std::size_t off = raw_inverted_tets(tree, in, s, bo, stats_off);
  bo.unfold_backward = true;
  const std::size_t on = raw_inverted_tets(tree, in, s, bo, stats_on);
  const std::size_t moved_off = stats_off.n_unfolded, moved_on = stats_on.n_unfolded;
  INFO("raw inverted tetrahedra without the rule " << off << ", with it " << on << " (" << moved_on << " moved)");
  CHECK(moved_off == 0);
  CHECK(moved_on > 0);
  CHECK(on < off);
}

// The steps of the interior octants' staircase (BoundaryOctantOptions::in_plane_cosine): where the
// level changes along a flat face (the feature level near a box's edges) the interior region
// has a step whose face stands square to the surface; the closest points of its nodes run in
// the face's plane and its boundary octant is flat (diagnose3d on this box: 44, 109, 194 folded
// boundary octants at levels 3, 4, 5). Along the summed normals of the nodes' free faces none
// folds.
TEST_CASE("step nodes projected along their free faces' summed normal fold no boundary octant of a box",
          "[pipeline3d][boundary_octants]") {
  TriangleSoup soup;
  const P3 lo(0.013, 0.021, 0.037), size(1.0, 0.7, 0.45);
  for (int k = 0; k < 8; ++k) soup.vertices.push_back(lo + P3(k & 1, (k >> 1) & 1, (k >> 2) & 1).cwiseProduct(size));
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    soup.triangles.push_back({f[0], f[1], f[2]});
    soup.triangles.push_back({f[0], f[2], f[3]});
  }
  SurfaceBoundary s{Surface(soup)};
  for (int level : {3, 4}) {
    s.set_global_level(level);
    s.set_max_level(level + 2);
    RefineOptions ro;
    ro.max_level = level + 4;
    const ControlFn<3> control = [&](const Box<3>& b) { return s.control_level(b); };
    const Orthtree<3> tree = balance_2to1(subdivide_by_control(s.root_box(), control, ro), BalanceKind::Full);
    Flags in = interior_flags(classify(tree, s));
    remove_pinches(tree, in);
    keep_largest_components(tree, in, s.n_components());
    BoundaryOctantOptions bo;
    bo.in_plane_cosine = 0.0;
    BoundaryOctantStats stats_off, stats_on;
    const std::size_t off = raw_inverted_tets(tree, in, s, bo, stats_off);
    bo.in_plane_cosine = 0.01;
    const std::size_t on = raw_inverted_tets(tree, in, s, bo, stats_on);
    const std::size_t rays_off = stats_off.n_ray, rays_on = stats_on.n_ray;
    INFO("level " << level << ": raw inverted tetrahedra by closest points " << off << ", along the summed normals "
                  << on << " (" << rays_on << " rays)");
    CHECK(off > 0);  // the box has steps: without the rule their octants fold
    CHECK(rays_off == 0);
    CHECK(rays_on > 0);
    CHECK(on == 0);
  }
}

// A run refused before it built a tree (the octants over Options3d::max_cells) has no work bound
// for a lattice draw: none is made, and the refusal is the first lattice's, of the same type.
TEST_CASE("mesh3d's lattice draws keep a refusal before any tree as it was", "[pipeline3d]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.level = 4;
  opt.max_cells = 1000;
  std::vector<std::string> lines;
  std::string one, drawn;
  try {
    Options3d single = opt;
    single.lattice_draws = 0;
    mesh3d(s, single);
  } catch (const LimitError& e) {
    one = e.what();
  }
  try {
    mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  } catch (const LimitError& e) {
    drawn = e.what();
  }
  CHECK_FALSE(one.empty());
  CHECK(drawn == one);
  // No draw, and no progress line about draws: a draw's tree would be as large.
  CHECK(std::none_of(lines.begin(), lines.end(), [](const std::string& l) { return l.find("lattice") != std::string::npos; }));
  CHECK(s.root_shift() == P3::Zero());
}

TEST_CASE("mesh3d's flat-buffer retry: made under its angle, kept only where the smallest angle rises", "[pipeline3d]") {
  // sphere966 at level 3 with the retry's bar above its smallest angle: the retry is made, but a
  // sphere has no flat face, so the flat buffer drops nothing, the mesh is the same and the first
  // stands (a retry that stands: the data test of spool level 5 turned).
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.level = 3;
  opt.flat_retry_below_deg = 0.0;
  const Result3d plain = mesh3d(s, opt);
  CHECK_FALSE(plain.flat_retry_made);
  opt.flat_retry_below_deg = 35.0;
  REQUIRE(summarize_quality(plain.fe.mesh).min_angle_deg < 35.0);
  std::vector<std::string> lines;
  const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  CHECK(r.flat_retry_made);
  CHECK_FALSE(r.flat_retry);
  CHECK(r.fe.mesh.points == plain.fe.mesh.points);
  CHECK(r.fe.mesh.solid.node == plain.fe.mesh.solid.node);
  const auto has = [&](const std::string& text) {
    return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
  };
  CHECK(has("under 35: once more without the interior octants whose faces lie flat"));
  CHECK(has("; the mesh before it stands"));
  CHECK(s.root_shift() == P3::Zero());
}

// Options3d::draw_max_volume_error: a mesh that loses more of the volume than it is degraded,
// and the draws run; when every run is degraded the valid one that loses the least stands.
// sphere966 at level 3 loses a little on every lattice, so with no loss allowed all three runs
// are made and ranked by their volume error; with the default (10%) the first lattice stands.
TEST_CASE("mesh3d's lattice draws take a mesh that loses more of the volume than allowed as degraded", "[pipeline3d]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.level = 3;
  opt.n_threads = 1;
  const Result3d first = mesh3d(s, opt);
  CHECK(first.lattice_draws_run == 0);
  const double first_error = measure_fidelity(first.fe.mesh, s, 1).volume_rel_error;
  REQUIRE(first_error > 0.0);
  REQUIRE(first_error < opt.draw_max_volume_error);

  std::vector<double> errors;  // each run's, in order
  for (int k = 0; k <= 2; ++k) {
    Options3d one = opt;
    one.lattice_draws = 0;
    s.set_root_shift(lattice_draw_shift(k));
    errors.push_back(measure_fidelity(mesh3d(s, one).fe.mesh, s, 1).volume_rel_error);
  }
  s.set_root_shift(P3::Zero());
  CHECK(errors[0] == first_error);
  REQUIRE(errors[1] != errors[0]);  // the lattices differ

  opt.draw_max_volume_error = 0.0;
  std::vector<std::string> lines;
  const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  CHECK(r.lattice_draws_run == 2);
  const int best = static_cast<int>(std::min_element(errors.begin(), errors.end()) - errors.begin());
  CHECK(r.lattice_draw == best);
  CHECK(measure_fidelity(r.fe.mesh, s, 1).volume_rel_error == errors[static_cast<std::size_t>(best)]);
  CHECK(validate(r.fe.mesh, surface_validation(s)).valid);
  const auto n_lost = std::count_if(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("% of the volume lost: once more with the lattice shifted") != std::string::npos;
  });
  CHECK(n_lost == 2);
  CHECK(s.root_shift() == P3::Zero());

  // The draws after a run that lost only volume build on at most volume_draw_effort x its
  // octants: at half of them draw 1 is refused by that bound at its first tree, and nothing
  // is left for draw 2. The first lattice's mesh stands.
  opt.volume_draw_effort = 0.5;
  lines.clear();
  const Result3d capped = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  CHECK(capped.lattice_draws_run == 1);
  CHECK(capped.lattice_draw == 0);
  CHECK(capped.fe.mesh.points == first.fe.mesh.points);
  const auto has = [&](const std::string& text) {
    return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
  };
  CHECK(has("lattice draw 1: refused ("));
  CHECK(has("0.5x the octants of the first run, which lost only volume"));
  CHECK(has("lattice draw 2: no work bound left; not made"));
  CHECK(s.root_shift() == P3::Zero());
}

TEST_CASE("SurfaceBoundary::set_root_scale enlarges the root cube and moves the levels with it", "[pipeline3d][size]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  const Box<3> root = s.root_box();
  std::vector<double> curvature(static_cast<std::size_t>(s.surface().n_triangles()));
  for (std::int32_t t = 0; t < s.surface().n_triangles(); ++t) curvature[t] = s.curvature_level(t);
  s.set_root_scale(1.5);
  CHECK(s.root_scale() == 1.5);
  CHECK(s.root_box().extent()[0] == Approx(1.5 * root.extent()[0]));
  CHECK((s.root_box().center() - root.center()).norm() < 1e-12 * root.extent()[0]);
  // A curvature level asks for cells of a given size: in a cube 1.5x as large, log2(1.5) more.
  for (std::int32_t t = 0; t < s.surface().n_triangles(); ++t)
    if (std::isfinite(curvature[t])) CHECK(s.curvature_level(t) == Approx(curvature[t] + std::log2(1.5)));
  s.set_root_scale(1.0);
  CHECK(s.root_box().extent()[0] == root.extent()[0]);
  for (std::int32_t t = 0; t < s.surface().n_triangles(); ++t) CHECK(s.curvature_level(t) == curvature[t]);
}

// The element count follows the size between the levels' 8x steps; a size that is a level's
// octant gives that level's mesh, point for point.
TEST_CASE("mesh3d with Options3d::size: a level's octant is that level, sizes between give counts between",
          "[pipeline3d][size]") {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  Options3d opt;
  opt.n_threads = 2;
  opt.level = 3;
  const Result3d l3 = mesh3d(s, opt);
  opt.level = 4;
  const Result3d l4 = mesh3d(s, opt);
  CHECK(l3.level == 3);
  CHECK(l3.root_scale == 1.0);
  CHECK(l3.cell_size == s.root_box().extent()[0] / 8);
  const double side = s.root_box().extent()[0];

  Options3d sized = opt;
  sized.level = 7;  // not used with a size
  sized.size = side / 8;
  const Result3d same = mesh3d(s, sized);
  CHECK(same.level == 3);
  CHECK(same.root_scale == 1.0);
  CHECK(same.fe.mesh.points == l3.fe.mesh.points);
  CHECK(same.fe.mesh.solid.node == l3.fe.mesh.solid.node);

  std::size_t last = l3.fe.mesh.solid.size();
  for (const double share : {0.8, 0.6}) {  // level-4 octants 1.6x and 1.2x the default's
    sized.size = share * side / 8;
    std::vector<std::string> lines;
    const Result3d r = mesh3d(s, sized, [&](const std::string& m) { lines.push_back(m); });
    INFO("size " << sized.size << ": " << r.fe.mesh.solid.size() << " tetrahedra");
    CHECK(r.level == 4);
    CHECK(r.root_scale == Approx(2 * share));
    CHECK(r.cell_size == Approx(sized.size));
    CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& l) { return l.find("size ") == 0; }));
    CHECK(r.fe.mesh.solid.size() > last);
    CHECK(r.fe.mesh.solid.size() < l4.fe.mesh.solid.size());
    last = r.fe.mesh.solid.size();
    const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
    INFO(v.summary());
    CHECK(v.valid);
    CHECK(measure_fidelity(r.fe.mesh, s, 2).volume_rel_error < 0.03);
  }
  CHECK(s.root_scale() == Approx(1.2));  // left as the last run set it
}
