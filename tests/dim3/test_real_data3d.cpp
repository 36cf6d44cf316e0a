// Real-data regression of `mesh3d` (issue 6): every closed surface of ../shared/data/3d at level
// 4 through the whole pipeline, then the validator (positive volumes, conforming, interface =
// boundary faces on the surface within 1e-10 of the size, Euler characteristic). Shapes that
// are known to fail today are tagged [!mayfail] so that the run still records them; a thrown
// GeometryError counts as a failure too.
//
// Measured state (session 4, CLI, default options, 2-core shared machine):
//   sphere966 L4  valid    25728 tets, min dihedral 27.97 deg, volume error 0.72%,  1.0 s
//   sphere966 L5  valid   190752 tets, min dihedral 27.44 deg, volume error 0.16%, 10.5 s
//   sphere966 L6  valid  1479648 tets, min dihedral 25.54 deg, volume error 0.04%, 44.6 s
//   spool L4      valid    53444 tets, min dihedral  9.42 deg, volume error 17.1%,  5.9 s
//                 (flanges thinner than 1.5 level-4 octants over 69% of the area are not meshed);
//                 session 8: the thickness retry (Options3d::thin_retry_cells) keeps them: valid,
//                 163244 tets, min dihedral 2.59 deg, volume error 3.22%, 6.8 s CPU
//   fandisk L4    session 6: valid through the last try with facing projections only (every
//                 try before is refused at the thin lips: ~18 inverted tets and ~20 folded
//                 interface triangles left after the untangling), 131238 tets, min dihedral
//                 11.79 deg, volume error 1.61%, 94 s wall / 47 s CPU (CLI, 3 repairs)
//   rotor L4      valid but 34.5% of the volume lost: 51% of the area is on blades thinner than
//                 half a level-4 octant; refining the surface octants gives inverted tets, and
//                 the valid coarse mesh stands; session 8: the thickness retry loses 29.7%;
//                 session 35: a lattice draw loses 22.7%
//   anchor L4     session 5: valid through the run without the buffer rule (the run with it is
//                 refused: rim nodes of one-octant slabs in two-octant arms project through the
//                 arm), 242386 tets, min dihedral 8.25 deg, volume error 0.66%, 27.1 s; at
//                 level 5 valid with the buffer (386976 tets, 3.76 deg, 1.47%, 26.7 s)
//   spool L5      session 5: valid without the buffer rule, 394868 tets, 2.41 deg, 1.85%, 84 s
//                 (too slow for this test)
//   elephant L4   session 7: valid through the run without the buffer rule after refining
//                 around the islands its thin legs/trunk/tail leave (Options3d::
//                 island_refinements, thin_cells), 1172552 tets, min dihedral 1.10 deg, volume
//                 error 0.32%, 5 repairs (CLI numbers in the commit message)
// The whole [data] run is about 76 s (45 s CPU) in Release, mostly the refused shapes' repairs;
// session 6 (fandisk meshed through all five tries, elephant refused without the last): 179 s
// wall / 109 s CPU on the shared 2-core machine (264 s / 132 s with elephant's last try too);
// session 7 (elephant valid, its run without the buffer rule directly): 243 s wall.
// After merging the faster dihedral optimiser (2026-12-02, CLI --threads 1): sphere966 L4/L5
// 28.17/27.67 deg, spool L4 9.66 deg, anchor L4 276042 tets 8.29 deg 0.59%, fandisk L4 180486
// tets 11.50 deg 2.03% (4 repairs), elephant L4 1168938 tets 1.10 deg 0.31%, 148 s CPU; the
// [data] run 155-161 s wall.
// Issue 6, quality (session q3, CLI --threads 1): the tetrahedra under 10 deg all stood in
// boundary octants on interface caps at feature lines (experiments/diagnose3d --pipeline
// --quality); feature snapping now pushes the nodes it leaves on crowded concave lines into a face
// (BoundaryOctantOptions::off_line) and the optimiser moves bad nodes at creases along the faces
// (TetOptimizeOptions::tangent_below_deg): sphere966 L4/L5 byte-identical (28.17/27.67 deg),
// spool L4 2.59 -> 10.24 deg (163244 tets, 3.17% volume error, 6.5 s CPU), anchor L4 8.29 ->
// 8.73 (276042 tets, 0.58%, 20 s), fandisk L4 11.50 -> 12.21 (180486 tets, 2.03%, 20 s),
// elephant L4 1.10 -> 1.63 (1168754 tets, 0.31%, 154 s). Left under 10 deg: anchor's quad
// bridging a convex feature edge, elephant's tetrahedra at fixed corners.
// Issue 6, session h1 (CLI --threads 1): after the first dihedral pass, three more in which the
// nodes snapped onto feature lines slide along them, aiming at 20 deg (the last with crease
// moves below 20 deg): sphere966 L4 byte-identical, spool L4 10.24 -> 14.30 deg, anchor L4 8.73
// -> 12.73, fandisk L4 12.21 -> 13.18 (same tets; volume errors within 0.01 points).
// The sanitizer build runs sphere966 L4 and spool L4 only: the cases tagged [slow] are left out
// by its ctest command (tests/CMakeLists.txt).

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/planar_frame.hpp"
#include "thrown.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

struct DataRun {
  bool buffer_dropped = false;
  bool buffer_fallback = false;
  bool facing_projection = false;
  bool thickness_refined = false;
  bool features_dropped = false;
  bool thickness_early = false;
  double min_dihedral_deg = 0.0;
  double volume_rel_error = 1.0;
  std::size_t edges_contracted = 0;
  std::size_t concave_swaps = 0;
  int level_raised = 0;
  bool surface_uniform = false;
  int lattice_draw = 0;
};

/// The surface at `path` through mesh3d with `opt`, then the validator and the fidelity checks;
/// `lines`, when given, receives the progress lines.
DataRun mesh_and_validate_file(const std::string& path, const Options3d& opt, std::vector<std::string>* lines = nullptr) {
  SurfaceBoundary s = SurfaceBoundary::from_file(path);
  const int level = opt.level;
  const Result3d r = lines ? mesh3d(s, opt, [lines](const std::string& m) { lines->push_back(m); }) : mesh3d(s, opt);
  const Mesh<3>& m = r.fe.mesh;
  REQUIRE(m.solid.size() > 0);
  const ValidateOptions<3> vo = surface_validation(s);
  const ValidationReport v = validate(m, vo);
  INFO(path << " level " << level << ": " << v.summary());
  CHECK(v.valid);
  const QualitySummary q = summarize_quality(m);
  CHECK(q.min_angle_deg > 0.0);
  const Fidelity3d f = measure_fidelity(m, s, 1);
  CHECK(f.max_node_distance <= vo.boundary_tolerance);
  CHECK(f.volume_rel_error < 0.25);
  return {r.buffer_dropped,   r.buffer_fallback, r.facing_projection, r.thickness_refined,
          r.features_dropped, r.thickness_early, q.min_angle_deg,     f.volume_rel_error,
          r.n_edges_contracted, r.n_concave_swaps, r.level_raised, r.surface_uniform, r.lattice_draw};
}

DataRun mesh_and_validate(const std::string& name, const Options3d& opt) {
  return mesh_and_validate_file(std::string(FEBEMESH_DATA_DIR) + "/3d/" + name + ".off", opt);
}

DataRun mesh_and_validate(const std::string& name, int level, int max_repairs = 2, bool retry_facing = true,
                          double buffer = Options3d{}.buffer) {
  Options3d opt;
  opt.level = level;
  opt.buffer = buffer;
  opt.max_repairs = max_repairs;  // failures cost time
  opt.retry_facing = retry_facing;
  return mesh_and_validate(name, opt);
}

}  // namespace

TEST_CASE("mesh3d data: sphere966 level 4 and 5", "[data][pipeline3d]") {
  // The sanitizer build (test::sanitized()) runs level 4 only.
  for (int level : test::sanitized() ? std::vector<int>{4} : std::vector<int>{4, 5}) {
    const DataRun d = mesh_and_validate("sphere966", level);
    CHECK(!d.buffer_dropped);
    CHECK(!d.buffer_fallback);
    CHECK(!d.facing_projection);
    CHECK(d.min_dihedral_deg >= 25.0);
    CHECK(d.volume_rel_error < 0.01);
  }
}

TEST_CASE("mesh3d data: spool level 4 (its thin flanges kept by the thickness retry)", "[data][pipeline3d]") {
  // The first mesh is valid but loses 17.1% of the volume in the flanges thinner than 1.5
  // level-4 octants; the retry with two octants across every part (thickness level, up to level
  // 6) and without the buffer rule is valid at its first tree (CLI --threads 1: 163244 tets, min
  // dihedral 2.59 deg, volume error 3.22%). Its 4 tetrahedra under 10 deg stood on interface
  // caps at a concave feature line; with the nodes pushed off it and the optimiser's moves along
  // creases: 10.24 deg, 3.17% (issue 6 asks for 10 deg); with the feature-line nodes sliding
  // along their lines (session h1): 14.30 deg, 3.17%. Its worst two then sat around a concave
  // surface edge (283 deg inside); with concave surface swaps (edge_removal, session 23): 20.00
  // deg, 3.16% (CLI), at issue 6's bar.
  const DataRun d = mesh_and_validate("spool", 4);
  CHECK(d.thickness_refined);
  CHECK(!d.facing_projection);
  CHECK(d.min_dihedral_deg >= 15.0);
  CHECK(d.concave_swaps > 0);  // what lifts it there
  CHECK(d.volume_rel_error < 0.05);
}

TEST_CASE("mesh3d data: spool level 6 with 4 octants across its thin parts (valid at its first tree)", "[data][pipeline3d][slow]") {
  // Refused by every try at the level (339 s CPU in session 31): its right flange ends in a lip
  // tapering from 0.022 to 0.010 thick, 1-3 level-7 octants, where the boundary octants fold.
  // The first tree has problems, so mesh3d builds the first tree with 4 octants across every
  // part (Options3d::thickness_probe: the thinnest of centroid and vertices,
  // SurfaceBoundary::thickness), up to level 8, no buffer rule; it has none and stands.
  // Measured (CLI, one thread): 3,186,690 tets, 15.85 deg, 0.16%, 28 s CPU, 664 MB; the
  // same mesh.msh as the thickness try after every refusal before it.
  Options3d opt;
  opt.level = 6;
  const DataRun d = mesh_and_validate("spool", opt);
  CHECK(d.thickness_early);
  CHECK_FALSE(d.facing_projection);
  CHECK(d.min_dihedral_deg >= 15.0);
  CHECK(d.volume_rel_error < 0.01);
}

TEST_CASE("mesh3d data: the thickness probe ends after a first round of untangling that leaves many inverted", "[data][pipeline3d]") {
  // Options3d::first_round_inverted_share, the probe's early end: fandisk at level 4 with 4
  // octants across its thin lips leaves 6% of its inverted tetrahedra after the first round
  // (181 of 3131 without feature snapping), which the probe's 2% refuses at once; without the share
  // the same tree is refused only after its nine rounds and the Escobar pass.
  const auto refusal = [](double share) {
    SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/fandisk.off");
    Options3d opt;
    opt.level = 4;
    opt = thickness_try_options(opt);
    opt.max_repairs = 0;
    opt.retry_facing = false;
    opt.snap_features = false;  // one try: no fallback
    opt.refused_thickness_cells = 0.0;
    opt.first_round_inverted_share = share;
    return test::thrown_message<GeometryError>([&] { mesh3d(s, opt); });
  };
  const std::string early = refusal(0.02), late = refusal(0.0);
  INFO(early);
  CHECK(early.find("the first round of untangling left") != std::string::npos);
  INFO(late);
  CHECK(late.find("the boundary octants cannot be built") != std::string::npos);
  CHECK(late.find("the first round of untangling") == std::string::npos);
}

TEST_CASE("mesh3d data: fandisk level 4 (valid with facing projections only)", "[data][pipeline3d][slow]") {
  // Every try before fails at the thin lips (closest points on the far sheet fold the boundary
  // octants); the last one, projections leaving through every free face and landing on surface
  // facing it, is valid after 4 repairs with the dihedral optimiser of session 7 (CLI: 180486
  // tets, 11.50 deg, 2.03%; 3 repairs and 131238 tets before it): the CLI's repair budget.
  // Issue 6 (the optimiser's moves along creases): 12.21 deg; feature-line nodes sliding: 13.18.
  const DataRun d = mesh_and_validate("fandisk", 4, Options3d{}.max_repairs);
  CHECK(d.facing_projection);
  CHECK_FALSE(d.thickness_early);  // the probe's first tree at the thickness level has problems
  CHECK(d.min_dihedral_deg >= 13.0);
  CHECK(d.volume_rel_error < 0.03);
}

TEST_CASE("mesh3d data: fandisk level 5 (valid in the facing try after a repair that made it worse)", "[data][pipeline3d][slow]") {
  // Every try is refused at the thin lips; the last one (facing projections) went 54 50 49 47 33
  // 25 35 problems over its repairs and stopped there ("made it worse"), while one repair more
  // makes it valid (Options3d::worse_repairs, 1 in that try). Here that try directly, which is
  // what mesh3d reaches (the CLI through all its tries: 768120 tets, 10.21 deg, 0.33% volume
  // error, 96 s CPU; this case alone 52 s CPU). Its tetrahedra under 15 deg (10.43 at worst) all
  // held one surface edge of 0.0012 among edges of 0.015-0.03 whose smooth end was a node
  // snapped next to a crease and kept fixed: edge contraction removed it (16.39 deg in both
  // kinds), and since the sliding passes free such nodes no contraction is needed.
  Options3d opt;
  opt.level = 5;
  opt = facing_try_options(opt);
  for (const bool hex : {false, true}) {
    opt.hex_dominant = hex;
    INFO((hex ? "hex-dominant" : "tetrahedra"));
    const DataRun d = mesh_and_validate("fandisk", opt);
    CHECK(d.min_dihedral_deg >= 15.0);
    CHECK(d.volume_rel_error < 0.01);
  }
}

TEST_CASE("mesh3d data: rotor level 4 (a lattice draw keeps more of its thin parts)", "[data][pipeline3d][slow]") {
  // Its blades are 0.02 thick, a third of a level-4 octant: the first mesh loses 34.5%. The
  // thickness retry (two octants across, capped at level 6 where the blades are 1.2 octants
  // thick) was valid through its try with facing projections and lost 29.7% (68398 tets, min
  // dihedral 16.61 deg), but its work bound (Options3d::thin_retry_effort, session 9) stops it
  // before: the first mesh stands (CLI --threads 1: 42 s CPU instead of 258 s). Session h1 (issue
  // 6): the island trial is undone unless no island is left, and the surface octants are then not
  // all refined for islands, so the retry reaches that facing try within its bound: valid, 68398
  // tets, 16.73 deg, 29.61% lost, 8.6 s CPU (was 19200 tets, 22.77 deg, 34.39%, 25.2 s).
  // Session 35: a mesh that loses more than 10% is degraded for the lattice draws
  // (Options3d::draw_max_volume_error), and on draw 1's lattice the thickness retry keeps more:
  // 22.74% lost (CLI --threads 1: 148683 tets, 17.63 deg, 12.7 s CPU for the three runs).
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/rotor.off");
  Options3d opt;
  opt.level = 4;
  opt.max_repairs = 2;  // failures cost time
  opt.n_threads = 1;
  std::vector<std::string> lines;
  const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(r.lattice_draws_run == 2);
  CHECK(r.lattice_draw > 0);
  CHECK(summarize_quality(r.fe.mesh).min_angle_deg >= 15.0);
  const double lost = measure_fidelity(r.fe.mesh, s, 1).volume_rel_error;
  CHECK(lost < 0.25);
  CHECK(lost > opt.draw_max_volume_error);  // the blades still thinner than the octants
  CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& l) {
    return l.find("% of the volume lost: once more with the lattice shifted") != std::string::npos;
  }));
}

TEST_CASE("mesh3d data: rotor level 5 (valid, its blades lost: the island trial is undone)", "[data][pipeline3d][slow]") {
  // Its blades (0.02 thick, 1.2 level-6 octants) fall apart into islands. Refining around them
  // (the island trial, above the share limit) left islands (1125 -> 1167, or 1241 -> 419 without
  // the buffer rule) and sheets of interior octants one octant thick in the blades, whose
  // boundary octants folded: ~2200 problems per repair, refused by the work bound after 7.3 CPU
  // minutes. The trial is now kept only when no island is left, and the octants on the surface
  // are then not all refined for the islands either: valid through the facing try with the
  // blades lost (CLI --threads 1: 184572 tets, 18.09 deg, 28.9% volume error, 140 s CPU, of
  // which the thickness retry that stops at its work bound is more than half). Here without
  // that retry, whose bound keeps this mesh.
  Options3d opt;
  opt.level = 5;
  opt.thin_retry_cells = 0.0;
  opt.lattice_draws = 0;  // the first lattice's mesh: draws triple the time
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/rotor.off");
  const Result3d r = mesh3d(s, opt);
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(r.facing_projection);
  CHECK(summarize_quality(r.fe.mesh).min_angle_deg >= 15.0);
  CHECK(measure_fidelity(r.fe.mesh, s, 1).volume_rel_error < 0.30);
}

TEST_CASE("mesh3d data: anchor level 4 (valid without the buffer rule)", "[data][pipeline3d][slow]") {
  // With the buffer rule the one-octant slabs in its two-octant-thick arms fold their boundary
  // octants (rim nodes project through the arm); the run without the buffer is valid. Issue 6:
  // 8.29 -> 8.73 deg (one of its two places under 10 deg was an interface cap at a concave
  // feature line). Feature-line nodes sliding along their lines (session h1): 12.73 deg. Edge
  // removal after the sweeps (Options3d::remove_edges_below_deg): 19.56 deg. Since session 31
  // that is the first try (Options3d::buffer_last): the same mesh, without the refused try.
  const DataRun d = mesh_and_validate("anchor", 4);
  INFO("min dihedral " << d.min_dihedral_deg << " deg");
  CHECK(!d.buffer_dropped);
  CHECK(!d.buffer_fallback);
  CHECK(!d.facing_projection);
  CHECK(d.min_dihedral_deg >= 19.0);
  CHECK(d.volume_rel_error < 0.02);
}

TEST_CASE("mesh3d data: spool level 5 turned (a face flat just above a lattice plane; the flat buffer's retry)", "[data][pipeline3d][slow]") {
  // Orientation o22 of experiments/orientations3d.sh: (x, y, z) -> (-z, y, x), exact. An interior
  // node 0.0012 under one of its flat faces leaves two tetrahedra at 11.75 deg that no node move
  // mends; without the interior octants whose faces lie flat under the surface (the retry,
  // Options3d::flat_retry_below_deg) 16.79 deg (session 36).
  const SurfaceBoundary given = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/spool.off");
  Eigen::Matrix3d turn;
  turn << 0, 0, -1, 0, 1, 0, 1, 0, 0;
  SurfaceBoundary s(turned_surface(given.surface(), turn), given.options());
  Options3d opt;
  opt.level = 5;
  Options3d off = opt;
  off.flat_retry_below_deg = 0.0;
  const Result3d first = mesh3d(s, off);
  CHECK_FALSE(first.flat_retry_made);
  const double first_deg = summarize_quality(first.fe.mesh).min_angle_deg;
  CHECK(first_deg < 13.0);
  std::vector<std::string> lines;
  const Result3d r = mesh3d(s, opt, [&](const std::string& m) { lines.push_back(m); });
  CHECK(r.flat_retry_made);
  CHECK(r.flat_retry);
  CHECK(r.lattice_draw == 0);
  const ValidationReport v = validate(r.fe.mesh, surface_validation(s));
  INFO(v.summary());
  CHECK(v.valid);
  CHECK(summarize_quality(r.fe.mesh).min_angle_deg >= 16.0);
  const Fidelity3d f = measure_fidelity(r.fe.mesh, s, 1);
  CHECK(f.volume_rel_error < 0.03);
  CHECK(f.volume_rel_error <= measure_fidelity(first.fe.mesh, s, 1).volume_rel_error + 0.002);
  CHECK(std::any_of(lines.begin(), lines.end(), [](const std::string& l) { return l.find("flat buffer: not degraded") != std::string::npos; }));
}

TEST_CASE("mesh3d data: anchor level 5 (no tetrahedron under 10 deg)", "[data][pipeline3d][slow]") {
  // Five tetrahedra of 9.45 deg around a surface edge across a concave feature line, whose
  // interface triangles meet at 62 deg: no node move gets them past 15.5 deg. Edge removal
  // after the sweeps (Options3d::remove_edges_below_deg; CLI 14.38 deg).
  const DataRun d = mesh_and_validate("anchor", 5);
  INFO("min dihedral " << d.min_dihedral_deg << " deg");
  CHECK(d.min_dihedral_deg >= 13.0);
  CHECK(d.volume_rel_error < 0.02);
}

TEST_CASE("mesh3d data: elephant level 4 (valid after refining around its islands)", "[data][pipeline3d][slow]") {
  // Its legs, trunk and tail are thinner than the level-4 octants: they fall apart (24-38
  // octants dropped as islands) and lose handles. The octants around the islands and on surface
  // thinner than 1.5 of their size are refined (Options3d::island_refinements) before the
  // boundary octants are built. Both runs with the buffer rule are still refused (inverted tets
  // at the maximum level; a repair that makes it worse); the run without it is valid after 5
  // repairs, one of them the refinement of the octants on the surface for a lost handle (Euler
  // characteristic -1, expected -2). Here that run directly (buffer 0), which is what mesh3d
  // reaches: measured 1172552 tets, min dihedral 1.10 deg, volume error 0.32%; issue 6 (CLI):
  // 1.63 deg, its worst tetrahedra at feature corners fixed where its facet creases end in
  // smooth skin. Session 15: those creases are not snapped to (Options3d::faceted_free_ends;
  // 69% of the line ends are free): 1172412 tets, 13.80 deg, 0.35%, 47.8 s CPU instead of 77.6.
  const DataRun d = mesh_and_validate("elephant", 4, 6, false, 0.0);
  CHECK(!d.facing_projection);
  CHECK(d.features_dropped);
  CHECK(d.min_dihedral_deg >= 12.0);
  CHECK(d.volume_rel_error < 0.01);
}

TEST_CASE("mesh3d examples: the bundled machined parts that mesh today (examples/3d)", "[data][pipeline3d]") {
  // Gmsh STL exports (examples/3d/README.md), with the CLI's defaults. Measured (session 50,
  // CLI --threads 1): bracket L4 31,172 tets, 19.56 deg, 4.84% volume error, 0.5 s; gear L5
  // 157,257 tets, 20.73 deg, 1.02%, 1.9 s. (Not here: the runs that stand only with the surface
  // at one level after 16-232 s of refused tries, session 51: the block at levels 4-6, the
  // flange and the tee at level 6; the block at level 4 is the [slow] case below, the tee at
  // level 4 the one after it.)
  const std::string dir = std::string(FEBEMESH_SOURCE_DIR) + "/examples/3d/";
  struct Case {
    const char* part;
    int level;
  };
  for (const Case c : test::sanitized() ? std::vector<Case>{{"bracket", 4}} : std::vector<Case>{{"bracket", 4}, {"gear", 5}}) {
    INFO(c.part << " level " << c.level);
    Options3d opt;
    opt.level = c.level;
    const DataRun d = mesh_and_validate_file(dir + c.part + ".stl", opt);
    CHECK(d.min_dihedral_deg >= 15.0);
    CHECK(d.volume_rel_error < 0.06);
  }
}

TEST_CASE("mesh3d examples: the pipe tee at level 4 is meshed at level 5 (walls 0.6 of a level-4 octant)", "[data][pipeline3d][slow]") {
  // Every try at level 4 is refused (its walls are thinner than the octants; its first tree's
  // fault is its topology, so no thickness probe there), cheaply: the run is raised one level,
  // and the raise now runs the thickness probe as level 5 asked directly does, whose first tree
  // stands (before session 50 the raise was refused and the run ended with an invalid mesh of
  // 193 tets). Measured (CLI --threads 1 --lattice-draws 0): 1,103,298 tets, 20.00 deg, 0.41%
  // volume error, 29 s CPU; the same mesh.msh as --level 5, and as level 4 with the draws (67 s).
  Options3d opt;
  opt.level = 4;
  opt.lattice_draws = 0;  // the draws at level 4 are refused too, and cost 38 s more
  const std::string path = std::string(FEBEMESH_SOURCE_DIR) + "/examples/3d/tee.stl";
  const DataRun d = mesh_and_validate_file(path, opt);
  CHECK(d.level_raised == 1);
  CHECK(d.thickness_early);
  CHECK(d.min_dihedral_deg >= 15.0);
  CHECK(d.volume_rel_error < 0.01);
}

TEST_CASE("mesh3d examples: the block is meshed with its surface at one level (Options3d::uniform_after_refusal)", "[data][pipeline3d][slow]") {
  // A pocket and a bore meeting a cross bore 0.1 above the floor. With the feature level the
  // octants change level along the flat faces, the staircase's steps fold their boundary
  // octants and every try at level 4 is refused (session 50: refused at levels 4 and 6, invalid
  // at level 5); with the surface at the one level the facing try stands. Measured (CLI
  // --threads 1, session 51): 161,714 tets, 22.38 deg, 0.73% volume error, 14.7 s CPU; since
  // session 52 that try comes right after the first (a faceted part): the same mesh in 7.2 s.
  Options3d opt;
  opt.level = 4;
  opt.lattice_draws = 0;
  const std::string path = std::string(FEBEMESH_SOURCE_DIR) + "/examples/3d/block.stl";
  const DataRun d = mesh_and_validate_file(path, opt);
  CHECK(d.surface_uniform);
  CHECK(d.level_raised == 0);
  CHECK(d.min_dihedral_deg >= 15.0);
  CHECK(d.volume_rel_error < 0.02);
}

TEST_CASE("mesh3d examples: on a faceted part the one-level try comes right after the first (Options3d::uniform_early_faceted)", "[data][pipeline3d][slow]") {
  // The flange's STL is faceted (66% of its feature lines' ends free: not snapped to). Its
  // first try at level 4 is refused; with the surface at one level the facing try stands at
  // once. Measured (CLI --threads 1, session 52): 210,952 tets, 24.06 deg, 0.77% volume error,
  // 4.7 s CPU; in session 51's order (the facing and buffer tries with the levels first, then
  // lattice draws) 416,606 tets, 12.59 deg, 2.00%, 17.8 s.
  Options3d opt;
  opt.level = 4;
  const std::string path = std::string(FEBEMESH_SOURCE_DIR) + "/examples/3d/flange.stl";
  std::vector<std::string> lines;
  const DataRun d = mesh_and_validate_file(path, opt, &lines);
  CHECK(d.surface_uniform);
  CHECK(d.features_dropped);
  CHECK(d.lattice_draw == 0);
  CHECK(d.min_dihedral_deg >= 20.0);
  CHECK(d.volume_rel_error < 0.015);
  // The order: the one-level try before any other try with the levels.
  const auto first = [&](const char* what) {
    return std::find_if(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  const auto early = first("a faceted surface, so at once with the surface at level 4 only");
  REQUIRE(early != lines.end());
  CHECK(first("with facing projections only") > early);
  CHECK(first("with the buffer rule") > early);
}
