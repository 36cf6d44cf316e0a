// The 3D pipeline on real data: sphere966.off at level 4 gives a valid mesh (positive,
// conforming, interface = boundary faces on the surface, V - E + F - C = 1) whose volume is
// within a few percent of the surface's; `febemesh mesh3d` refuses an open surface.

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/pipeline3d.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

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
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "febemesh_test_open_cylinder";
  std::filesystem::remove_all(out);
  const std::string cmd = std::string(FEBEMESH_CLI) + " mesh3d " + FEBEMESH_DATA_DIR + "/3d/open-cylinder.off -o " +
                          out.string() + " --quiet 2> " + out.string() + ".err";
  const int status = std::system(cmd.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK_FALSE(std::filesystem::exists(out));
  std::filesystem::remove(out.string() + ".err");
}
