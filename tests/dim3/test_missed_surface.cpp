// missed_surface: the points of a surface that its BE mesh misses. A cube's own triangles miss
// nothing; without its top face, the top's points farther from the sides than the allowance
// are missed, each at its distance to the nearest side, and nothing else.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "dim3/missed_surface.hpp"
#include "dim3/surface_checks.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

const std::vector<Point<3>> cube_points = {Point<3>(0, 0, 0), Point<3>(1, 0, 0), Point<3>(1, 1, 0), Point<3>(0, 1, 0),
                                           Point<3>(0, 0, 1), Point<3>(1, 0, 1), Point<3>(1, 1, 1), Point<3>(0, 1, 1)};
const std::vector<std::array<std::int32_t, 3>> cube_triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7},
                                                                 {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
                                                                 {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

SurfaceBoundary unit_cube() {
  TriangleSoup s;
  s.vertices = cube_points;
  for (const auto& t : cube_triangles) s.triangles.push_back({t[0], t[1], t[2]});
  Surface surface(s);
  validate_surface(surface, "cube");
  return SurfaceBoundary(std::move(surface));
}

/// A BE mesh of the cube's triangles but those of `skip` (indices into cube_triangles).
Mesh<3> be_mesh(const std::vector<int>& skip) {
  Mesh<3> m;
  for (const Point<3>& p : cube_points) m.add_point(p);
  for (int t = 0; t < static_cast<int>(cube_triangles.size()); ++t) {
    if (std::find(skip.begin(), skip.end(), t) != skip.end()) continue;
    const auto& v = cube_triangles[static_cast<std::size_t>(t)];
    m.interface.add(ElemType::Tri3, {VertexId{v[0]}, VertexId{v[1]}, VertexId{v[2]}});
  }
  return m;
}

}  // namespace

TEST_CASE("missed_surface finds the surface the BE mesh misses, at its distance", "[missed_surface]") {
  const SurfaceBoundary cube = unit_cube();
  const auto allow = [](double a) { return [a](const Point<3>&) { return a; }; };

  CHECK(missed_surface(be_mesh({}), cube, 0.05, allow(1e-9)).empty());
  CHECK(missed_surface(Mesh<3>{}, cube, 0.05, allow(0.0)).empty());  // no BE mesh: nothing to measure

  const std::vector<MissedPoint> top = missed_surface(be_mesh({2, 3}), cube, 0.05, allow(0.1));
  REQUIRE(!top.empty());
  for (const MissedPoint& m : top) {
    CAPTURE(m.p.transpose(), m.distance);
    CHECK(m.p.z() == 1.0);
    const double to_side = std::min({m.p.x(), 1.0 - m.p.x(), m.p.y(), 1.0 - m.p.y()});
    CHECK(m.distance == Approx(to_side).margin(1e-12));
    CHECK(m.distance > 0.1);
  }
  // Samples near the top's centre (0.5 from every side) are among them; a finer spacing finds more.
  const auto farthest = std::max_element(top.begin(), top.end(), [](const MissedPoint& a, const MissedPoint& b) {
    return a.distance < b.distance;
  });
  CHECK(farthest->distance > 0.5 - 0.05);
  CHECK(missed_surface(be_mesh({2, 3}), cube, 0.02, allow(0.1)).size() > top.size());
  // An allowance above the farthest point misses nothing.
  CHECK(missed_surface(be_mesh({2, 3}), cube, 0.05, allow(0.5 + 1e-9)).empty());
}
