// The 2D pipeline end to end: every output is checked by core's validator (DESIGN.md validity),
// on the bundled examples and the shared glyphs, for the three element kinds.

#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "core/quality.hpp"
#include "core/validate.hpp"
#include "core/write_msh.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

struct Run {
  Result2d r;
  ValidationReport v;
  Fidelity2d f;
};

Run run(const std::string& path, double level, ElementKind kind) {
  CurveBoundary curve(read_domain(path));
  curve.set_global_level(level);
  Options2d opt;
  opt.level = level;
  opt.elements = kind;
  opt.keep_stages = false;
  Run out{mesh2d(curve, opt), {}, {}};
  ValidateOptions<2> vo;
  vo.expected_euler = curve.n_components() - curve.n_holes();
  const Box<2> bb = curve.bounding_box();
  vo.boundary_distance = [&](const Point<2>& p) { return curve.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * (bb.hi - bb.lo).norm();
  out.v = validate<2>(out.r.fe.mesh, vo);
  out.f = measure_fidelity(out.r.fe, curve);
  return out;
}

std::string example(const std::string& name) { return std::string(FEBEMESH_SOURCE_DIR) + "/examples/" + name; }
std::string glyph(const std::string& name) { return std::string(FEBEMESH_DATA_DIR) + "/2d/" + name; }

}  // namespace

TEST_CASE("mesh2d gives valid FE and BE meshes on the bundled examples", "[pipeline2d]") {
  for (const std::string file : {"bracket.json", "flange.json", "naca0012.json"}) {
    for (ElementKind kind : {ElementKind::Tri, ElementKind::Quad, ElementKind::Mixed}) {
      for (double level : {5.0, 6.0}) {
        INFO(file << " " << name(kind) << " level " << level);
        const Run out = run(example(file), level, kind);
        INFO(out.v.summary());
        CHECK(out.v.valid);
        CHECK(out.r.fe.mesh.interface.size() > 0);
        // The FE area equals the BE polygon's area to round-off.
        CHECK(std::abs(out.f.fe_area - out.f.be_polygon_area) <= 1e-10 * out.f.exact_area);
        CHECK(out.f.area_rel_error < 0.05);
      }
    }
  }
}

TEST_CASE("mesh2d gives valid meshes on the shared glyphs", "[pipeline2d][data]") {
  for (const std::string file : {"DejaVuSans-U0038.svg", "DejaVuSans-U0041.svg", "DejaVuSans-U0042.svg",
                                 "DejaVuSans-U004F.svg", "DejaVuSans-U0065.svg", "DejaVuSerif-Bold-U0052.svg",
                                 "NimbusSans-Regular-U0061.svg", "NimbusSans-Regular-U0067.svg"}) {
    for (double level : {5.0, 6.0}) {
      INFO(file << " level " << level);
      const Run out = run(glyph(file), level, ElementKind::Tri);
      INFO(out.v.summary());
      CHECK(out.v.valid);
    }
  }
}

TEST_CASE("area error and Hausdorff distance fall with the level", "[pipeline2d]") {
  std::vector<double> area, haus;
  for (double level : {4.0, 5.0, 6.0, 7.0}) {
    const Run out = run(example("flange.json"), level, ElementKind::Tri);
    REQUIRE(out.v.valid);
    area.push_back(out.f.area_rel_error);
    haus.push_back(out.f.hausdorff_rel);
  }
  for (std::size_t k = 1; k < area.size(); ++k) {
    INFO("level step " << k << ": area " << area[k - 1] << " -> " << area[k] << ", hausdorff " << haus[k - 1] << " -> "
                       << haus[k]);
    CHECK(haus[k] < haus[k - 1]);
  }
  // Second order overall: three halvings of h shrink the Hausdorff distance at least ~16x.
  CHECK(haus.back() < haus.front() / 16.0);
}

TEST_CASE("mesh2d is deterministic", "[pipeline2d]") {
  const Run a = run(example("bracket.json"), 6, ElementKind::Mixed);
  const Run b = run(example("bracket.json"), 6, ElementKind::Mixed);
  CHECK(msh_string<2>(a.r.fe.mesh) == msh_string<2>(b.r.fe.mesh));
}
