// AABB tree queries against brute force over all triangles.

#include <catch2/catch.hpp>

#include <limits>

#include "dim3/aabb_tree.hpp"
#include "dim3/read_surface.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

const Surface& elephant() {
  static const Surface s(read_surface(std::string(FEBEMESH_DATA_DIR) + "/3d/elephant.off"));
  return s;
}

double brute_distance(const Surface& s, const P3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : s.triangles()) {
    const TrianglePoint q = closest_on_triangle(p, s.vertex(t[0]), s.vertex(t[1]), s.vertex(t[2]));
    best = std::min(best, (q.point - p).norm());
  }
  return best;
}

P3 point_near(const Box<3>& b, int x, int y, int z) {
  // Integers in [0, 1000] mapped onto the box enlarged by half its size on each side.
  const P3 t(x / 1000.0, y / 1000.0, z / 1000.0);
  return b.lo - 0.5 * b.extent() + (2.0 * b.extent()).cwiseProduct(t);
}

}  // namespace

TEST_CASE("closest point matches brute force", "[aabb_tree][property]") {
  const Surface& s = elephant();
  const AabbTree tree(s.vertices(), s.triangles());
  febemesh::test::prop("closest distance = min over all triangles", 200, [&] {
    const int x = *rc::gen::inRange(0, 1001), y = *rc::gen::inRange(0, 1001), z = *rc::gen::inRange(0, 1001);
    const P3 p = point_near(s.bounding_box(), x, y, z);
    const AabbTree::Closest c = tree.closest(p);
    RC_ASSERT(c.triangle >= 0);
    const double d = std::sqrt(c.distance2);
    RC_ASSERT(std::abs(d - brute_distance(s, p)) <= 1e-12 * (1.0 + d));
    // The reported point is on the reported triangle, at the reported parameters.
    const auto& q = tree.points(c.triangle);
    const P3 from_uv = q[0] + c.where.u * (q[1] - q[0]) + c.where.v * (q[2] - q[0]);
    RC_ASSERT((from_uv - c.where.point).norm() <= 1e-9 * s.bounding_box().extent().norm());
  });
}

TEST_CASE("closest point with a hint is closest point without", "[aabb_tree]") {
  // The same triangle and bits whatever the hint: the hint only bounds the search. Points near
  // the surface (as the tet optimiser asks: the answer's neighbours and far triangles as hints)
  // and far from it, among them vertices and points straight out of them (ties between the
  // triangles around a vertex, which the tree order breaks).
  const Surface& s = elephant();
  const AabbTree tree(s.vertices(), s.triangles());
  const double diag = s.bounding_box().extent().norm();
  std::uint64_t seed = 8;
  const auto uniform = [&] {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(seed >> 11) / double(1ULL << 53);
  };
  int n_checked = 0;
  for (int i = 0; i < 3000; ++i) {
    P3 p;
    const std::int32_t t0 = static_cast<std::int32_t>(uniform() * s.n_triangles());
    const P3 n = s.normal(t0);
    switch (i % 3) {
      case 0: p = s.vertex(s.triangle(t0)[0]) + (uniform() - 0.3) * 0.01 * diag * n; break;
      case 1: p = (s.vertex(s.triangle(t0)[0]) + s.vertex(s.triangle(t0)[1]) + s.vertex(s.triangle(t0)[2])) / 3.0 +
                  (uniform() - 0.5) * 0.02 * diag * P3(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5); break;
      default: p = point_near(s.bounding_box(), int(uniform() * 1000), int(uniform() * 1000), int(uniform() * 1000));
    }
    const AabbTree::Closest want = tree.closest(p);
    for (const std::int32_t hint : {want.triangle, t0, static_cast<std::int32_t>(uniform() * s.n_triangles()),
                                    std::int32_t{-1}, std::int32_t{s.n_triangles()}}) {
      const AabbTree::Closest got = tree.closest(p, hint);
      REQUIRE(got.triangle == want.triangle);
      REQUIRE(got.distance2 == want.distance2);
      REQUIRE(got.where.point == want.where.point);
      ++n_checked;
    }
  }
  CHECK(n_checked == 15000);
}

TEST_CASE("closest point regions on a single triangle", "[aabb_tree]") {
  const P3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  CHECK(closest_on_triangle(P3(0.2, 0.2, 1), a, b, c).region == TriangleRegion::Face);
  CHECK(closest_on_triangle(P3(0.5, -1, 0), a, b, c).region == TriangleRegion::Edge0);
  CHECK(closest_on_triangle(P3(1, 1, 0), a, b, c).region == TriangleRegion::Edge1);
  CHECK(closest_on_triangle(P3(-1, 0.5, 0), a, b, c).region == TriangleRegion::Edge2);
  CHECK(closest_on_triangle(P3(-1, -1, 0), a, b, c).region == TriangleRegion::Vertex0);
  CHECK(closest_on_triangle(P3(2, -0.1, 0), a, b, c).region == TriangleRegion::Vertex1);
  CHECK(closest_on_triangle(P3(-0.1, 2, 0), a, b, c).region == TriangleRegion::Vertex2);
  const TrianglePoint e1 = closest_on_triangle(P3(1, 1, 0), a, b, c);
  CHECK(e1.u == Approx(0.5));
  CHECK(e1.v == Approx(0.5));
}

TEST_CASE("box and segment candidates are supersets of the exact answers", "[aabb_tree][property]") {
  const Surface& s = elephant();
  const AabbTree tree(s.vertices(), s.triangles());
  febemesh::test::prop("box overlap and segment crossing agree with all triangles", 100, [&] {
    const P3 p = point_near(s.bounding_box(), *rc::gen::inRange(0, 1001), *rc::gen::inRange(0, 1001),
                            *rc::gen::inRange(0, 1001));
    const P3 q = point_near(s.bounding_box(), *rc::gen::inRange(0, 1001), *rc::gen::inRange(0, 1001),
                            *rc::gen::inRange(0, 1001));
    Box<3> box = Box<3>::empty();
    box.expand(p);
    box.expand(p + 0.05 * (q - p));
    bool overlap_ref = false, crosses_ref = false, crosses = false;
    for (const Triangle& t : s.triangles()) {
      overlap_ref = overlap_ref || box_triangle_overlap(box, s.vertex(t[0]), s.vertex(t[1]), s.vertex(t[2]));
      crosses_ref = crosses_ref ||
                    segment_triangle(p, q, s.vertex(t[0]), s.vertex(t[1]), s.vertex(t[2])) != Crossing::Miss;
    }
    tree.for_each_on_segment(p, q, [&](std::int32_t t) {
      const auto& c = tree.points(t);
      crosses = crosses || segment_triangle(p, q, c[0], c[1], c[2]) != Crossing::Miss;
    });
    RC_ASSERT(tree.overlaps(box) == overlap_ref);
    RC_ASSERT(crosses == crosses_ref);
  });
}

TEST_CASE("box-triangle separating axis test", "[aabb_tree]") {
  Box<3> box;
  box.lo = P3(0, 0, 0);
  box.hi = P3(1, 1, 1);
  CHECK(box_triangle_overlap(box, P3(0.5, 0.5, 0.5), P3(3, 0, 0), P3(0, 3, 0)));   // corner inside
  CHECK(box_triangle_overlap(box, P3(-1, -1, 0.5), P3(3, -1, 0.5), P3(-1, 3, 0.5)));  // slices through
  CHECK_FALSE(box_triangle_overlap(box, P3(1.5, 0, 0), P3(3, 0, 0), P3(1.5, 3, 3)));
  // Plane x + y + z = 3.2 misses the box (its corner (1,1,1) has 3) although the boxes overlap.
  CHECK_FALSE(box_triangle_overlap(box, P3(3.2, 0, 0), P3(0, 3.2, 0), P3(0, 0, 3.2)));
  CHECK(box_triangle_overlap(box, P3(3, 0, 0), P3(0, 3, 0), P3(0, 0, 3)));  // touches the corner
}
