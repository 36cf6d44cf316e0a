// Feature edges, corners and lines.

#include <catch2/catch.hpp>

#include <set>

#include "dim3/features.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface_checks.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

Surface unit_cube() {
  TriangleSoup s;
  s.vertices = {P3(0, 0, 0), P3(1, 0, 0), P3(1, 1, 0), P3(0, 1, 0),
                P3(0, 0, 1), P3(1, 0, 1), P3(1, 1, 1), P3(0, 1, 1)};
  s.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return Surface(s);
}

Surface data(const std::string& name) {
  Surface s(read_surface(std::string(FEBEMESH_DATA_DIR) + "/3d/" + name));
  validate_surface(s, name);
  return s;
}

/// Every feature edge lies on exactly one line; lines end at corners or close.
void check_lines(const Surface& s, const Features& f) {
  std::multiset<std::int32_t> on_lines;
  for (std::size_t l = 0; l < f.lines().size(); ++l) {
    const FeatureLine& line = f.lines()[l];
    REQUIRE(line.vertices.size() == line.edges.size() + 1);
    for (std::size_t i = 0; i < line.edges.size(); ++i) {
      on_lines.insert(line.edges[i]);
      CHECK(f.line_of(f.feature_edge_index(line.edges[i])) == static_cast<std::int32_t>(l));
      CHECK(s.find_edge(line.vertices[i], line.vertices[i + 1]) == line.edges[i]);
    }
    if (line.closed) {
      CHECK(line.vertices.front() == line.vertices.back());
    } else {
      CHECK((f.is_corner(line.vertices.front()) || f.feature_degree(line.vertices.front()) != 2));
      CHECK((f.is_corner(line.vertices.back()) || f.feature_degree(line.vertices.back()) != 2));
    }
  }
  CHECK(on_lines == std::multiset<std::int32_t>(f.feature_edges().begin(), f.feature_edges().end()));
}

}  // namespace

TEST_CASE("a cube has 12 feature edges, 8 corners and 12 lines", "[features]") {
  const Surface cube = unit_cube();
  const Features f(cube);
  CHECK(f.n_feature_edges() == 12);
  CHECK(f.n_corners() == 8);
  CHECK(f.lines().size() == 12);
  CHECK(f.free_end_share() == 0.0);  // every line ends at a corner where 3 meet
  for (std::int32_t v = 0; v < 8; ++v) CHECK(f.feature_degree(v) == 3);
  check_lines(cube, f);
  // Face diagonals are flat, cube edges are right angles.
  for (std::int32_t e = 0; e < cube.n_edges(); ++e)
    CHECK(f.dihedral(e) == Approx(f.is_feature_edge(e) ? M_PI / 2 : 0.0).margin(1e-12));
  // Snapping helpers.
  const auto hit = f.nearest_corner(P3(1.1, 0.9, 1.2));
  CHECK(f.corners()[hit.corner] == 6);
  CHECK(hit.distance == Approx(std::sqrt(0.01 + 0.01 + 0.04)));
  const std::int32_t line = f.line_of(f.feature_edge_index(cube.find_edge(0, 1)));
  const auto lp = f.closest_on_line(line, P3(0.25, -1, -2));
  CHECK((lp.point - P3(0.25, 0, 0)).norm() < 1e-12);
  CHECK(lp.distance == Approx(std::sqrt(5.0)));
}

TEST_CASE("a threshold above 90 degrees leaves the cube smooth except its corners as cones", "[features]") {
  const Surface cube = unit_cube();
  FeatureOptions o;
  o.angle_deg = 100.0;
  const Features f(cube, o);
  CHECK(f.n_feature_edges() == 0);
  CHECK(f.n_corners() == 8);  // angle defect pi/2 at each cube corner > 60 deg
}

TEST_CASE("features of the data surfaces", "[features]") {
  const Surface sphere = data("sphere966.off");
  const Features fs(sphere);
  CHECK(fs.n_feature_edges() == 0);
  CHECK(fs.n_corners() == 0);
  for (const char* name : {"fandisk.off", "anchor.off", "rotor.off", "spool.off"}) {
    INFO(name);
    const Surface s = data(name);
    const Features f(s);
    CHECK(f.n_feature_edges() > 0);
    check_lines(s, f);
    // Machined parts: lines end where others meet, a few at a tangent-continuous blend (fandisk 0.08).
    CHECK(f.free_end_share() < 0.1);
  }
  // elephant.off's skin is faceted: most of its 30-degree creases start and stop in smooth
  // surface, which is how mesh3d tells it from a machined part (Options3d::faceted_free_ends).
  const Surface elephant = data("elephant.off");
  const Features fe(elephant);
  check_lines(elephant, fe);
  CHECK(fe.free_end_share() > 0.5);
}
