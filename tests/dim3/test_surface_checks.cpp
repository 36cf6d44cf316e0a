// Surface checks: the fast (AABB-pruned) self-intersection search agrees with all pairs; the
// individual checks find what they should on small hand-made surfaces.

#include <catch2/catch.hpp>

#include "dim3/read_surface.hpp"
#include "dim3/surface.hpp"
#include "dim3/surface_checks.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

TriangleSoup tetrahedron(const P3& shift) {
  TriangleSoup s;
  s.vertices = {shift, shift + P3(1, 0, 0), shift + P3(0, 1, 0), shift + P3(0, 0, 1)};
  s.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return s;
}

TriangleSoup two_tetrahedra(const P3& shift) {
  TriangleSoup a = tetrahedron(P3::Zero()), b = tetrahedron(shift);
  for (const P3& p : b.vertices) a.vertices.push_back(p);
  for (const Triangle& t : b.triangles) a.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
  return a;
}

}  // namespace

TEST_CASE("self-intersections: pruned search equals all pairs", "[surface_checks]") {
  for (double d : {0.2, 0.5, 0.79, 0.81, 1.0, 2.0}) {
    INFO("shift " << d);
    Surface s(two_tetrahedra(P3(d, 0.1, 0.1)));
    const AabbTree tree(s.vertices(), s.triangles());
    const auto fast = self_intersections(s, tree);
    CHECK(fast == self_intersections_ref(s));
    CHECK(fast.empty() == (d > 0.8));  // apart once the corner (d, .1, .1) leaves x + y + z <= 1
  }
  const Surface sphere(read_surface(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off"));
  const AabbTree tree(sphere.vertices(), sphere.triangles());
  CHECK(self_intersections(sphere, tree).empty());
  CHECK(self_intersections_ref(sphere).empty());
}

TEST_CASE("coplanar overlapping triangles intersect; touching at a vertex does not", "[surface_checks]") {
  const P3 a[3] = {P3(0, 0, 0), P3(1, 0, 0), P3(0, 1, 0)};
  const P3 b[3] = {P3(0.2, 0.2, 0), P3(1.2, 0.2, 0), P3(0.2, 1.2, 0)};
  CHECK(triangles_intersect(a, b));
  const P3 c[3] = {P3(1, 0, 0), P3(2, 0, 0), P3(1, 1, 0)};  // shares the point (1, 0, 0) only
  CHECK_FALSE(triangles_intersect(a, c));
  const P3 d[3] = {P3(0.2, 0.2, -1), P3(0.2, 0.2, 1), P3(3, 3, 0)};  // pierces a
  CHECK(triangles_intersect(a, d));
}

TEST_CASE("closedness, manifoldness and orientation checks", "[surface_checks]") {
  Surface tet(tetrahedron(P3::Zero()));
  CHECK(boundary_edges(tet).empty());
  CHECK(non_manifold_edges(tet).empty());
  CHECK(non_manifold_vertices(tet).empty());
  CHECK(degenerate_triangles(tet).empty());
  CHECK(is_consistently_oriented(tet));
  CHECK(tet.volume() == Approx(1.0 / 6.0));

  TriangleSoup open = tetrahedron(P3::Zero());
  open.triangles.pop_back();
  CHECK(boundary_edges(Surface(open)).size() == 3);

  // Two tetrahedra touching at one vertex: every edge manifold, the vertex is not.
  TriangleSoup bow = two_tetrahedra(P3(1, 0, 0));
  for (Triangle& t : bow.triangles)
    for (auto& v : t)
      if (v == 4) v = 1;
  Surface touching(bow);
  CHECK(non_manifold_edges(touching).empty());
  CHECK(non_manifold_vertices(touching) == std::vector<std::int32_t>{1});

  // One triangle reversed: orient_outward repairs it.
  TriangleSoup bad = tetrahedron(P3::Zero());
  std::swap(bad.triangles[2][1], bad.triangles[2][2]);
  Surface s(bad);
  CHECK_FALSE(is_consistently_oriented(s));
  CHECK(orient_outward(s, "bad") == 1);
  CHECK(is_consistently_oriented(s));
  CHECK(s.volume() == Approx(1.0 / 6.0));

  // A zero-area triangle.
  TriangleSoup flat = tetrahedron(P3::Zero());
  flat.vertices[3] = P3(0.5, 0.5, 0.0);
  CHECK_FALSE(degenerate_triangles(Surface(flat)).empty());
}
