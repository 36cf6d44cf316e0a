// Surface checks: the fast (AABB-pruned) self-intersection search agrees with all pairs; the
// individual checks find what they should on small hand-made surfaces.

#include <catch2/catch.hpp>

#include "core/error.hpp"
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

TEST_CASE("triangles that share no vertex meet when they cross, overlap or touch", "[surface_checks]") {
  const P3 a[3] = {P3(0, 0, 0), P3(1, 0, 0), P3(0, 1, 0)};
  const P3 b[3] = {P3(0.2, 0.2, 0), P3(1.2, 0.2, 0), P3(0.2, 1.2, 0)};
  CHECK(triangles_intersect(a, b));
  // Coplanar, touching at the point (1, 0, 0) only (a corner of each, not a shared vertex of
  // the surface): two sheets meet there.
  const P3 c[3] = {P3(1, 0, 0), P3(2, 0, 0), P3(1, 1, 0)};
  CHECK(triangles_intersect(a, c));
  const P3 apart[3] = {P3(1.01, 0, 0), P3(2, 0, 0), P3(1.01, 1, 0)};
  CHECK_FALSE(triangles_intersect(a, apart));
  const P3 inside[3] = {P3(0.1, 0.1, 0), P3(0.3, 0.1, 0), P3(0.1, 0.3, 0)};  // within a, edges apart
  CHECK(triangles_intersect(a, inside));
  CHECK(triangles_intersect(inside, a));
  const P3 d[3] = {P3(0.2, 0.2, -1), P3(0.2, 0.2, 1), P3(3, 3, 0)};  // pierces a
  CHECK(triangles_intersect(a, d));
  // Not coplanar: a corner on a's interior, or an edge lying in a's plane across it: touches.
  const P3 corner_on[3] = {P3(0.2, 0.2, 0), P3(0.2, 0.2, 1), P3(1, 1, 1)};
  CHECK(triangles_intersect(a, corner_on));
  const P3 edge_in_plane[3] = {P3(0.5, -1, 0), P3(0.5, 1, 0), P3(0.5, 0, 1)};  // an edge in a's plane, across a
  CHECK(triangles_intersect(a, edge_in_plane));
  const P3 above[3] = {P3(0.2, 0.2, 0.01), P3(0.2, 0.2, 1), P3(1, 1, 1)};
  CHECK_FALSE(triangles_intersect(a, above));
}

TEST_CASE("two spheres crossing exactly through each other's edges are self-intersecting", "[surface_checks]") {
  // sphere966 and a copy moved by its radius along x: mirror images about x = 5, so every point
  // where they cross lies on an edge of both (the contacts are touches, no proper crossing; the
  // search once counted proper crossings only and passed this surface, which mesh3d then failed
  // on with 'the boundary octants cannot be built' instead of naming the input's fault).
  const TriangleSoup one = read_surface(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  TriangleSoup two = one;
  const auto n = static_cast<std::int32_t>(one.vertices.size());
  for (const P3& p : one.vertices) two.vertices.push_back(p + P3(10, 0, 0));
  for (const Triangle& t : one.triangles) two.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  const Surface s(two);
  const AabbTree tree(s.vertices(), s.triangles());
  const auto fast = self_intersections(s, tree);
  CHECK_FALSE(fast.empty());
  CHECK(fast == self_intersections_ref(s));
  // Moved apart (by 2.5 radii): no contact.
  TriangleSoup apart = one;
  for (const P3& p : one.vertices) apart.vertices.push_back(p + P3(25, 0, 0));
  for (const Triangle& t : one.triangles) apart.triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  const Surface sa(apart);
  CHECK(self_intersections(sa, AabbTree(sa.vertices(), sa.triangles())).empty());
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

TEST_CASE("coordinates out of range are refused as such, not as degenerate triangles", "[surface_checks]") {
  const auto message = [](double scale, double shift) {
    TriangleSoup t = tetrahedron(P3::Zero());
    for (P3& p : t.vertices) p = p * scale + P3::Constant(shift);
    Surface s(t);
    try {
      (void)validate_surface(s, "t.off");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // Both overflowed or underflowed the predicates' products: "4 degenerate (zero-area) triangle(s)".
  CHECK_THAT(message(1e200, 0), Catch::StartsWith("t.off: coordinates up to 1e+200 exceed the largest accepted magnitude"));
  CHECK_THAT(message(1, 1e16), Catch::Contains("exceed the largest accepted magnitude 1e+15"));
  CHECK_THAT(message(1e-200, 0), Catch::StartsWith("t.off: the surface is 1e-200 across, under the smallest accepted extent"));
  CHECK(message(1e14, 0).empty());
  CHECK(message(1e-50, 0).empty());
  CHECK(message(1, 1e14).empty());
}
