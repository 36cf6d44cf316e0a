// Real-data regression of `mesh3d` (issue 6): every closed surface of ../shared/data/3d at level
// 4 through the whole pipeline, then the validator (positive volumes, conforming, interface =
// boundary faces on the surface within 1e-10 of the size, Euler characteristic). Shapes that
// are known to fail today (inverted boundary tets, lost topology; see the report of issue 6)
// are tagged [!mayfail] so that the run still records them; a thrown GeometryError counts as a
// failure too.

#include <catch2/catch.hpp>

#include <string>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/pipeline3d.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

void mesh_and_validate(const std::string& name, int level) {
  SurfaceBoundary s = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/" + name + ".off");
  Options3d opt;
  opt.level = level;
  opt.max_repairs = 2;  // failures cost time; a third repair has not helped in any measured run
  const Result3d r = mesh3d(s, opt);
  const Mesh<3>& m = r.fe.mesh;
  REQUIRE(m.solid.size() > 0);
  ValidateOptions<3> vo;
  if (s.euler_characteristic() % 2 == 0) vo.expected_euler = s.euler_characteristic() / 2;
  vo.boundary_distance = [&](const Point<3>& p) { return s.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * s.bounding_box().extent().norm();
  const ValidationReport v = validate(m, vo);
  INFO(name << " level " << level << ": " << v.summary());
  CHECK(v.valid);
  const QualitySummary q = summarize_quality(m);
  CHECK(q.min_angle_deg > 0.0);
  const Fidelity3d f = measure_fidelity(m, s, 1);
  CHECK(f.max_node_distance <= vo.boundary_tolerance);
  CHECK(f.volume_rel_error < 0.25);
}

}  // namespace

TEST_CASE("mesh3d data: sphere966 level 4 and 5", "[data][pipeline3d]") {
  mesh_and_validate("sphere966", 4);
  mesh_and_validate("sphere966", 5);
}

TEST_CASE("mesh3d data: spool level 4", "[data][pipeline3d]") { mesh_and_validate("spool", 4); }

TEST_CASE("mesh3d data: fandisk level 4 (known to fail: inverted boundary tets)", "[data][pipeline3d][!mayfail]") {
  mesh_and_validate("fandisk", 4);
}

TEST_CASE("mesh3d data: rotor level 4 (known to fail: valid, but 34.5% of the volume is lost in thin parts)", "[data][pipeline3d][!mayfail]") {
  mesh_and_validate("rotor", 4);
}

TEST_CASE("mesh3d data: anchor level 4 (known to fail: inverted boundary tets)", "[data][pipeline3d][!mayfail]") {
  mesh_and_validate("anchor", 4);
}

TEST_CASE("mesh3d data: elephant level 4 (known to fail: inverted boundary tets)", "[data][pipeline3d][!mayfail]") {
  mesh_and_validate("elephant", 4);
}
