// Performance work must not change meshes: threads give the same bytes as one thread, the fast
// quality pass gives the mesh of its slow twin, and large runs drop their stages (figures).

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "core/partitioned_sweep.hpp"
#include "core/smooth.hpp"
#include "core/write_msh.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/improve2d.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/report2d.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

std::string example(const std::string& name) { return std::string(FEBEMESH_SOURCE_DIR) + "/examples/" + name; }
std::string glyph(const std::string& name) { return std::string(FEBEMESH_DATA_DIR) + "/2d/" + name; }

Result2d run(const std::string& path, double level, ElementKind kind, int threads, int improve_rounds = 4) {
  CurveBoundary curve(read_domain(path));
  curve.set_global_level(level);
  Options2d opt;
  opt.level = level;
  opt.elements = kind;
  opt.keep_stages = false;
  opt.n_threads = threads;
  opt.improve_rounds = improve_rounds;
  return mesh2d(curve, opt);
}

}  // namespace

TEST_CASE("mesh2d gives the same mesh bytes with 1, 2 and 3 threads", "[pipeline2d][threads]") {
  struct Case {
    std::string file;
    double level;
    ElementKind kind;
  };
  // flange level 8 mixed: 40,746 interior quadrants, so the templates run in several runs
  // of quadrants (one a 4096) on every count above 1.
  const std::vector<Case> cases{{example("flange.json"), 7, ElementKind::Tri},
                                {example("flange.json"), 8, ElementKind::Mixed},
                                {example("bracket.json"), 6, ElementKind::Mixed},
                                {glyph("DejaVuSans-U0041.svg"), 6, ElementKind::Tri}};
  for (const Case& c : cases) {
    INFO(c.file << " level " << c.level);
    const Result2d one = run(c.file, c.level, c.kind, 1);
    REQUIRE(one.fe.mesh.solid.size() > 100);
    for (const int threads : {2, 3}) {
      INFO(threads << " threads");
      const Result2d more = run(c.file, c.level, c.kind, threads);
      CHECK(msh_string(one.fe.mesh) == msh_string(more.fe.mesh));
      CHECK(msh_string(one.fe.mesh, MshEncoding::Binary) == msh_string(more.fe.mesh, MshEncoding::Binary));
      // The projections run on the threads, their counts summed after.
      CHECK(one.stats.n_next_normal == more.stats.n_next_normal);
      CHECK(one.stats.n_walked == more.stats.n_walked);
      CHECK(one.stats.n_free_edges == more.stats.n_free_edges);
    }
  }
  // U0067 at level 5 walks along the curve for some projections and takes a further normal
  // for one: the counts summed over the threads are the serial ones.
  const Result2d one = run(glyph("NimbusSans-Regular-U0067.svg"), 5, ElementKind::Tri, 1);
  REQUIRE(one.stats.n_walked > 0);
  REQUIRE(one.stats.n_next_normal > 0);
  for (const int threads : {2, 3}) {
    const Result2d more = run(glyph("NimbusSans-Regular-U0067.svg"), 5, ElementKind::Tri, threads);
    CHECK(one.stats.n_walked == more.stats.n_walked);
    CHECK(one.stats.n_next_normal == more.stats.n_next_normal);
    CHECK(msh_string(one.fe.mesh) == msh_string(more.fe.mesh));
  }
}

TEST_CASE("the fast quality pass gives the mesh of its slow twin", "[pipeline2d][improve]") {
  for (const auto& [file, kind] : {std::pair{example("flange.json"), ElementKind::Tri},
                                   std::pair{example("bracket.json"), ElementKind::Mixed},
                                   std::pair{glyph("NimbusSans-Regular-U0067.svg"), ElementKind::Tri}}) {
    INFO(file);
    CurveBoundary curve(read_domain(file));
    curve.set_global_level(6);
    Result2d r = run(file, 6, kind, 1, 0);  // the mesh before the quality pass
    std::vector<std::uint8_t> locked(r.fe.mesh.points.size(), 0);
    for (std::size_t k = 0; k < r.fe.where.size(); ++k)
      locked[r.fe.where.nodes()[k]] = r.fe.where.locations()[k].kind == BoundaryLocation::Kind::Corner ? 1 : 2;
    // The pipeline's slide: along the node's own loop, never onto a corner.
    auto slide_for = [&](Mesh<2>& m, CurveLocations& where) -> SlideFn {
      return [&m, &where, &curve](std::int32_t v, const Point<2>& target) {
        const ClosestPoint<2> cp = curve.closest_point(target);
        if (cp.where.patch != where.at(v).patch || cp.where.kind == BoundaryLocation::Kind::Corner) return m.points[v];
        where.at(v) = cp.where;
        return Point<2>(cp.point);
      };
    };
    Mesh<2> slow = r.fe.mesh;
    CurveLocations where_slow = r.fe.where;
    const ImproveStats b = improve_mesh_ref(slow, locked, 4, slide_for(slow, where_slow));
    for (const int threads : {1, 2}) {  // (threads: the set-up and the mesh's smallest angle)
      INFO(threads << " threads");
      Mesh<2> fast = r.fe.mesh;
      CurveLocations where_fast = r.fe.where;
      ImproveOptions io;
      io.slide = slide_for(fast, where_fast);
      io.n_threads = threads;
      const ImproveStats a = improve_mesh(fast, locked, io);
      CHECK(a.flips == b.flips);
      CHECK(a.moves == b.moves);
      CHECK(a.min_angle_before == b.min_angle_before);
      CHECK(a.min_angle_after == b.min_angle_after);
      CHECK(a.flips + a.moves > 0);  // the pass did something to compare
      CHECK(msh_string(fast) == msh_string(slow));
    }
    // Started from a smoothing's at_rest, without the smallest angle (the pipeline's): the same
    // mesh as with neither. One more
    // smoothing (the pipeline's options) of the smoothed mesh, which leaves some nodes at rest
    // (flange level 6: 480 of 3,554).
    Mesh<2> smoothed = r.fe.mesh;
    SmoothOptions<2> so;
    so.parts = default_sweep_parts;
    so.min_move = quality_rounding_share;
    so.min_quality = false;
    so.fixed.assign(smoothed.points.size(), 0);
    for (const std::int32_t v : r.fe.where.nodes()) so.fixed[v] = 1;
    so.boundary_fixed = true;
    std::vector<std::uint8_t> at_rest;
    so.at_rest = &at_rest;
    smooth(smoothed, so);
    REQUIRE(at_rest.size() == smoothed.points.size());
    REQUIRE(std::count(at_rest.begin(), at_rest.end(), 1) > static_cast<std::ptrdiff_t>(smoothed.points.size() / 20));
    for (const int threads : {1, 2}) {
      INFO(threads << " threads, from at_rest");
      Mesh<2> without = smoothed, with = smoothed;
      CurveLocations where_without = r.fe.where, where_with = r.fe.where;
      std::vector<std::uint8_t> given = at_rest;
      ImproveOptions plain;
      plain.slide = slide_for(without, where_without);
      plain.n_threads = threads;
      const ImproveStats a = improve_mesh(without, locked, plain);
      // The pipeline's options: from at_rest, no smallest angle measured.
      ImproveOptions lean;
      lean.slide = slide_for(with, where_with);
      lean.n_threads = threads;
      lean.at_rest = &given;
      lean.measure_min = false;
      const ImproveStats b = improve_mesh(with, locked, lean);
      CHECK(given.empty());  // taken over
      CHECK(a.flips == b.flips);
      CHECK(a.moves == b.moves);
      CHECK(a.min_angle_after > 0.0);
      CHECK(b.min_angle_before == 0.0);  // not measured
      CHECK(b.min_angle_after == 0.0);
      CHECK(msh_string(with) == msh_string(without));
    }
  }
}

TEST_CASE("stages are kept only up to keep_stages_max_elements", "[pipeline2d]") {
  CurveBoundary curve(read_domain(example("flange.json")));
  curve.set_global_level(5);
  Options2d opt;
  opt.level = 5;
  opt.keep_stages = true;
  const Result2d kept = mesh2d(curve, opt);
  CHECK(kept.stages_kept);
  CHECK(kept.subdivided.n_leaves() > 1);
  CHECK(!kept.complex.boundary.empty());
  opt.keep_stages_max_elements = kept.fe.mesh.solid.size() - 1;
  const Result2d dropped = mesh2d(curve, opt);
  CHECK(!dropped.stages_kept);
  CHECK(dropped.complex.boundary.empty());
  CHECK(msh_string(dropped.fe.mesh) == msh_string(kept.fe.mesh));
}

TEST_CASE("report.json's quality measures are the same on 1, 2 and 3 threads", "[pipeline2d][threads]") {
  // NACA 0012 in mixed elements: triangles and quads, and a 16.6 deg trailing edge whose
  // elements are exempt; more than 4 chunks of 16,384 elements, so the extremes and the exempt
  // count are combined over chunks.
  const std::string file = example("naca0012.json");
  const Result2d r = run(file, 10, ElementKind::Mixed, 1);
  REQUIRE(r.fe.mesh.solid.size() > 4 * 16384);
  const CurveBoundary curve(read_domain(file));
  const Quality2d one = measure_quality(r.fe.mesh, curve, 1);
  REQUIRE(one.n_near_sharp_corners > 0);
  REQUIRE(one.quad_bar);
  CHECK(one.min_angle_away_deg > one.summary.min_angle_deg);  // the trailing edge's angles are left out
  for (const int threads : {2, 3}) {
    INFO(threads << " threads");
    const Quality2d more = measure_quality(r.fe.mesh, curve, threads);
    CHECK(more.min_angle_away_deg == one.min_angle_away_deg);
    CHECK(more.n_near_sharp_corners == one.n_near_sharp_corners);
    CHECK(more.quad_bar->min_quad_deg == one.quad_bar->min_quad_deg);
    CHECK(more.quad_bar->max_quad_deg == one.quad_bar->max_quad_deg);
    CHECK(more.quad_bar->min_triangle_deg == one.quad_bar->min_triangle_deg);
    CHECK(more.summary.min_angle_deg == one.summary.min_angle_deg);
    CHECK(more.summary.mean_scaled_jacobian == one.summary.mean_scaled_jacobian);
    CHECK(more.summary.n_slivers == one.summary.n_slivers);
  }
}
