// Real-data regression (issue 5): every 2D file of the shared data (FEBEMESH_DATA_DIR/2d) and
// every bundled example (examples/*.json), at levels 4 to 8 (issue 4's bar) and the three
// element kinds, meshed by the whole pipeline and checked by the core validator and the
// quality bars: triangles >= 20 deg away from input corners sharper than 20 deg (>= 29.5 in tri
// mode), quads within [30, 150] deg away from input corners sharper than 30 deg. The combinations that fail
// today are listed in known_failures and run in their own `[!mayfail]` test cases, named after
// the failure, so that CI stays green while the failures stay visible in every run (none today).

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/read_domain.hpp"
#include "pipeline_check.hpp"

using namespace febemesh;
using namespace febemesh::dim2;
namespace fs = std::filesystem;

namespace {

struct Combo {
  std::string file;  ///< path relative to FEBEMESH_DATA_DIR ("2d/x.svg") or the source ("examples/x.json")
  int level;
  ElementKind kind;
};

/// Failing today: none (all 11 files x 5 levels x 3 kinds valid when this was written). A
/// combination that starts failing goes here and into its own TEST_CASE named after the failure,
/// tagged "[data][!mayfail]", which calls check_combo on it.
struct KnownFailure {
  Combo combo;
  const char* failure;  ///< the test case name
};
const std::vector<KnownFailure> known_failures = {};

std::string full_path(const std::string& file) {
  return file.rfind("examples/", 0) == 0 ? std::string(FEBEMESH_SOURCE_DIR) + "/" + file
                                          : std::string(FEBEMESH_DATA_DIR) + "/" + file;
}

std::vector<std::string> data_files() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(fs::path(FEBEMESH_DATA_DIR) / "2d"))
    if (e.is_regular_file()) out.push_back("2d/" + e.path().filename().string());
  for (const auto& e : fs::directory_iterator(fs::path(FEBEMESH_SOURCE_DIR) / "examples"))
    if (e.path().extension() == ".json") out.push_back("examples/" + e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

bool same(const Combo& a, const Combo& b) { return a.file == b.file && a.level == b.level && a.kind == b.kind; }

bool is_known_failure(const Combo& c) {
  return std::any_of(known_failures.begin(), known_failures.end(),
                     [&](const KnownFailure& k) { return same(k.combo, c); });
}

/// Meshes one combination and checks it; a GeometryError or LimitError fails the check.
void check_combo(const Combo& c) {
  INFO(c.file << " level " << c.level << " " << name(c.kind));
  std::string refused;
  try {
    CurveBoundary curve(read_domain(full_path(c.file)));
    Options2d opt;
    opt.level = c.level;
    opt.elements = c.kind;
    opt.keep_stages = false;
    const test::PipelineOutcome out = test::run_pipeline(curve, opt);
    INFO(out.v.summary());
    CHECK(out.v.valid);
    CHECK(out.r.fe.mesh.interface.size() > 0);
    CHECK(out.f.max_node_distance_rel <= 1e-10);
    const double round_off = 4.0 * std::numeric_limits<double>::epsilon() * double(out.v.n_solid);
    CHECK(std::abs(out.f.fe_area - out.f.be_polygon_area) <= round_off * out.f.exact_area);
    CHECK(out.q.min_scaled_jacobian > 0.0);
    // Every corner of the curve is an interface node, unless the last repair reported it missed.
    CHECK(out.corners_off_mesh == out.r.stats.n_corners_missed);
    CurveBoundary bare(read_domain(full_path(c.file)));
    const AnglesAwayFromCorners tri = angles_away_from_sharp_corners(out.r.fe.mesh, bare, 20.0);
    const AnglesAwayFromCorners quad = angles_away_from_sharp_corners(out.r.fe.mesh, bare, 30.0);
    CHECK(tri.min_triangle_deg >= 20.0);
    // Beyond the bar: the corner-angle optimisation reaches 30 deg (the goal after it) on
    // every file in tri mode (measured 30.0 at worst); assert it with a small margin.
    if (c.kind == ElementKind::Tri) CHECK(tri.min_triangle_deg >= 29.5);
    // Quads split from the triangles of a wedge sharper than 20 deg (the NACA trailing edge,
    // 16.6 deg) reach beyond the exempt zone: there the bar is relaxed to [15, 165] (issue 4
    // note); everywhere else [30, 150] holds.
    const bool has_wedge = std::any_of(bare.corners().begin(), bare.corners().end(),
                                       [](const CurveCorner& k) { return k.angle_deg < 20.0; });
    CHECK(quad.min_quad_deg >= (has_wedge ? 15.0 : 30.0));
    CHECK(quad.max_quad_deg <= (has_wedge ? 165.0 : 150.0));
  } catch (const GeometryError& e) {
    refused = std::string("GeometryError: ") + e.what();
  } catch (const LimitError& e) {
    refused = std::string("LimitError: ") + e.what();
  }
  INFO(refused);
  CHECK(refused.empty());
}

}  // namespace

TEST_CASE("every shared 2D file and example meshes validly at levels 4-8, tri/quad/mixed", "[data][pipeline2d]") {
  const std::vector<std::string> files = data_files();
  REQUIRE(files.size() >= 3);
  // The sanitizer build (test::sanitized()) runs levels 4-5 only: levels 6-8 hold 98% of the
  // elements, and under ASan they would take most of CI's time.
  const std::vector<int> levels = test::sanitized() ? std::vector<int>{4, 5} : std::vector<int>{4, 5, 6, 7, 8};
  int n = 0, n_known = 0;
  for (const std::string& file : files)
    for (int level : levels)
      for (ElementKind kind : {ElementKind::Tri, ElementKind::Mixed, ElementKind::Quad}) {
        const Combo c{file, level, kind};
        if (is_known_failure(c)) {
          ++n_known;
          continue;
        }
        check_combo(c);
        ++n;
      }
  CHECK(n + n_known == int(files.size() * levels.size()) * 3);
}
