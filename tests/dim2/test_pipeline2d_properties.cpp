// Property-based validity of the whole 2D pipeline (issue 5) on random valid domains
// (domain_generators.hpp: the regime, the shrinking). CI budget: a few dozen cases per property;
// FEBEMESH_PROPERTY_CASES=10000 runs many more; a failure prints the seed (replay with
// RC_PARAMS="seed=S") and the shrunk case as a native JSON file, which goes to
// tests/dim2/regressions/ (replayed by test_regressions.cpp).

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.hpp"
#include "core/read_msh.hpp"
#include "core/write_msh.hpp"
#include "domain_generators.hpp"
#include "pipeline_check.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;
using febemesh::test::PipelineCase;

namespace {

/// What the cases measured, printed after each property so the numbers behind the quality
/// bound stay visible.
struct Tally {
  long cases = 0;
  long refused = 0;  ///< GeometryError (counted; the property fails on it in this regime)
  double min_angle = 180.0, min_sj = 1.0;
  int max_level = 0;
  void print(const char* what) const {
    std::printf("[property] %s: %ld cases, %ld GeometryError, min angle %.3g deg, min scaled Jacobian %.3g, "
                "levels up to %d\n",
                what, cases, refused, min_angle, min_sj, max_level);
  }
};

/// The case's domain meshed (on a root square `root_scale` x the default: --size's).
test::PipelineOutcome run_case(const PipelineCase& c, Tally& tally, double root_scale = 1.0) {
  CurveBoundary curve(test::to_domain(c.domain));
  if (root_scale != 1.0) curve.set_root_scale(root_scale);
  ++tally.cases;
  try {
    test::PipelineOutcome out = test::run_pipeline(curve, test::to_options(c));
    tally.min_angle = std::min(tally.min_angle, out.q.min_angle_deg);
    tally.min_sj = std::min(tally.min_sj, out.q.min_scaled_jacobian);
    tally.max_level = std::max(tally.max_level, c.domain.level);
    return out;
  } catch (const GeometryError& e) {
    ++tally.refused;
    RC_FAIL(std::string("GeometryError: ") + e.what());
  }
}

/// The case's domain meshed with its options changed by tweak(Options2d&), without the checks.
template <class Tweak> Result2d mesh_with(const PipelineCase& c, Tweak&& tweak) {
  CurveBoundary curve(test::to_domain(c.domain));
  Options2d opt = test::to_options(c);
  tweak(opt);
  if (opt.level != no_level) curve.set_global_level(opt.level);
  return mesh2d(curve, opt);
}

/// The validity contract on one output.
void check_valid(const test::PipelineOutcome& out) {
  RC_TAG(out.v.valid ? "valid" : "INVALID");
  if (!out.v.valid) RC_FAIL(out.v.summary());
  RC_ASSERT(out.r.fe.mesh.interface.size() > 0u);
  // Interface nodes on the curve within 1e-10 of the size.
  RC_ASSERT(out.f.max_node_distance_rel <= 1e-10);
  // FE area == BE polygon area to round-off: a sum of n_solid areas, each exact to a few ulps.
  const double round_off = 4.0 * std::numeric_limits<double>::epsilon() * double(out.v.n_solid);
  RC_ASSERT(std::abs(out.f.fe_area - out.f.be_polygon_area) <= round_off * out.f.exact_area);
  // Every corner of the curve is an interface node, unless the last repair reported it missed.
  RC_ASSERT(out.corners_off_mesh == out.r.stats.n_corners_missed);
  // Quality bound. The paper's templates promise none after smoothing and corner pulling; what
  // holds, measured over ~1000 random cases at levels 6-8 (issue 5 note): min angle >= 4.3 deg
  // (tri), 6.7 (mixed), asserted with a margin. Quad (split after the quality pass, then the
  // corner-angle optimisation): 100 cases, min angle 29.9 deg (session 2).
  RC_ASSERT(out.q.min_scaled_jacobian > 0.0);
  RC_ASSERT(out.q.min_angle_deg >= 2.0);
}

void validity_property(ElementKind kind, int ci_cases) {
  Tally tally;
  test::prop(std::string("whole pipeline output is valid, ") + name(kind), ci_cases, [&] {
    const PipelineCase c = *test::gen_pipeline_case(kind);
    check_valid(run_case(c, tally));
  });
  tally.print(name(kind));
}

}  // namespace

TEST_CASE("pipeline output is valid on random domains (tri)", "[property][pipeline2d]") {
  validity_property(ElementKind::Tri, 15);
}

TEST_CASE("pipeline output is valid on random domains (mixed)", "[property][pipeline2d]") {
  validity_property(ElementKind::Mixed, 15);
}

TEST_CASE("pipeline output is valid on random domains (quad)", "[property][pipeline2d]") {
  validity_property(ElementKind::Quad, 15);
}

// --size (CurveBoundary::set_root_scale): the same domains on a root square enlarged by a scale
// in [1, 2), so on lattices the levels alone never give; the same contract.
TEST_CASE("pipeline output is valid on random domains in an enlarged root square (--size)", "[property][pipeline2d][size]") {
  Tally tally;
  test::prop("whole pipeline output is valid at a root scale in [1, 2)", 15, [&] {
    const PipelineCase c = *test::gen_pipeline_case(ElementKind::Tri);
    const double scale = 1.0 + *rc::gen::inRange(0, 1000) / 1000.0;
    RC_TAG(scale < 1.5 ? "scale < 1.5" : "scale >= 1.5");
    check_valid(run_case(c, tally, scale));
  });
  tally.print("tri, enlarged root square");
}

TEST_CASE("pipeline is deterministic and its MSH reads back the same", "[property][pipeline2d]") {
  Tally tally;
  test::prop("same msh bytes twice; write + read back gives the same mesh", 4, [&] {
    const PipelineCase c = *test::gen_pipeline_case();
    const test::PipelineOutcome a = run_case(c, tally);
    const test::PipelineOutcome b = run_case(c, tally);
    const std::string msh = msh_string<2>(a.r.fe.mesh);
    RC_ASSERT(msh == msh_string<2>(b.r.fe.mesh));
    const Mesh<2> back = parse_msh<2>(msh);
    const Mesh<2>& m = a.r.fe.mesh;
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

TEST_CASE("threads give the one-thread mesh on random domains", "[property][pipeline2d][threads]") {
  // The flip decisions, the chain projections, the node lists and the free facets run on the
  // threads (session 39); 2 and 3 threads (ranges of unequal sizes) against one, every kind.
  Tally tally;
  test::prop("the same msh bytes and counts on 1, 2 and 3 threads", 6, [&] {
    const PipelineCase c = *test::gen_pipeline_case();
    const test::PipelineOutcome one = run_case(c, tally);
    for (const int threads : {2, 3}) {
      const Result2d more = mesh_with(c, [&](Options2d& opt) { opt.n_threads = threads; });
      RC_ASSERT(msh_string<2>(one.r.fe.mesh) == msh_string<2>(more.fe.mesh));
      RC_ASSERT(one.r.stats.n_next_normal == more.stats.n_next_normal);
      RC_ASSERT(one.r.stats.n_walked == more.stats.n_walked);
      RC_ASSERT(one.r.n_flips == more.n_flips);
    }
  });
  tally.print("threads");
}

TEST_CASE("leaving the outside unsplit gives the same mesh, from fewer quadrants", "[property][pipeline2d]") {
  Tally tally;
  test::prop("outside boxes unsplit: the same msh bytes", 4, [&] {
    PipelineCase c = *test::gen_pipeline_case();
    const test::PipelineOutcome pruned = run_case(c, tally);
    const Result2d full = mesh_with(c, [](Options2d& opt) { opt.split_outside = true; });
    RC_ASSERT(msh_string<2>(pruned.r.fe.mesh) == msh_string<2>(full.fe.mesh));
    RC_ASSERT(pruned.r.tree.n_leaves() <= full.tree.n_leaves());
    RC_TAG(pruned.r.tree.n_leaves() < full.tree.n_leaves() ? "fewer quadrants" : "as many quadrants");
  });
  tally.print("outside unsplit");
}

TEST_CASE("the FE area approaches the exact area as the level rises", "[property][pipeline2d]") {
  Tally tally;
  test::prop("BE distance to the curve falls over two levels and bounds the area error", 4, [&] {
    PipelineCase c = *test::gen_pipeline_case(ElementKind::Tri);
    RC_PRE(c.domain.level <= 7);  // three levels up to 9 keep the CI budget
    double perimeter = 0.0;
    {
      const CurveBoundary curve(test::to_domain(c.domain));
      for (std::size_t l = 0; l < curve.loops().size(); ++l) perimeter += curve.length(int(l));
    }
    std::vector<double> err, haus;
    int finest = 0;  // the first tree's finest leaf level
    const int level0 = c.domain.level;
    for (int k = 0; k < 3; ++k) {
      const test::PipelineOutcome out = run_case(c, tally);
      RC_ASSERT(out.v.valid);
      if (k == 0)
        for (std::size_t i = 0; i < out.r.tree.n_leaves(); ++i) finest = std::max(finest, int(out.r.tree.leaf(i).level));
      err.push_back(out.f.area_rel_error);
      haus.push_back(out.f.hausdorff);
      // The region between the BE polygon and the curve lies within the Hausdorff distance of
      // the curve: |FE area - exact area| <= perimeter x Hausdorff (1% margin for sampling),
      // plus the FE area's round-off (check_valid's: a polygonal domain has Hausdorff ~1e-16
      // and an area error of round-off only; seed 2112, case 701: 2.6e-14 of the area).
      const double round_off = 4.0 * std::numeric_limits<double>::epsilon() * double(out.v.n_solid);
      RC_ASSERT(out.f.area_rel_error * out.f.exact_area <=
                1.01 * perimeter * out.f.hausdorff + round_off * out.f.exact_area);
      ++c.domain.level;
    }
    RC_LOG() << "area errors " << err[0] << " " << err[1] << " " << err[2] << ", Hausdorff " << haus[0] << " "
             << haus[1] << " " << haus[2] << "\n";
    // The signed area error is not monotone (chords inside convex parts and outside concave ones
    // cancel: 777006 found 2.6e-6, 3.9e-6, 5.3e-6 at levels 6-8), but the distance that bounds it
    // never grows over two levels, and falls when they make every cell finer. Not where the
    // first tree already has cells two levels finer (the file's levels, or bends tighter than
    // the cells, refined whatever level was asked): there the largest distance can stay put
    // (session 12, 2000 cases at seed 31, case 805: a hole of radius 0.09 with two corners kept
    // cells of level 9 or finer at its bends, Hausdorff 8.67487e-5 at levels 6, 7 and 8, then
    // 2.63e-5 at 9).
    RC_LOG() << "finest leaf level " << finest << " at level " << level0 << "\n";
    // Distances at round-off (a polygonal domain's BE polygon is its boundary) do not count.
    const double noise = 1e-12 * perimeter;
    RC_ASSERT(haus[2] <= haus[0] + noise);
    if (finest < level0 + 2 && haus[0] > noise) RC_ASSERT(haus[2] < haus[0]);
  });
  tally.print("area convergence");
}
