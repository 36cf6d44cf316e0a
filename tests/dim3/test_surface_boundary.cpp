// SurfaceBoundary: the Boundary<3> answers on shapes whose answers are known.

#include <catch2/catch.hpp>

#include <cmath>
#include <map>

#include "core/error.hpp"
#include "dim3/surface_boundary.hpp"
#include "dim3/surface_checks.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
using Kind = BoundaryLocation::Kind;

namespace {

SurfaceBoundary unit_cube() {
  TriangleSoup s;
  s.vertices = {P3(0, 0, 0), P3(1, 0, 0), P3(1, 1, 0), P3(0, 1, 0),
                P3(0, 0, 1), P3(1, 0, 1), P3(1, 1, 1), P3(0, 1, 1)};
  s.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  Surface surface(s);
  validate_surface(surface, "cube");
  return SurfaceBoundary(std::move(surface));
}

const SurfaceBoundary& data(const std::string& name) {
  static std::map<std::string, SurfaceBoundary> cache;
  auto it = cache.find(name);
  if (it == cache.end())
    it = cache.emplace(name, SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/" + name)).first;
  return it->second;
}

Box<3> box(const P3& lo, const P3& hi) {
  Box<3> b;
  b.lo = lo;
  b.hi = hi;
  return b;
}

}  // namespace

TEST_CASE("closest point on a cube reports face, feature edge and corner", "[surface_boundary]") {
  const SurfaceBoundary cube = unit_cube();
  const auto face = cube.closest_point(P3(0.3, 0.6, -1));
  CHECK(face.where.kind == Kind::Smooth);
  CHECK(face.distance == Approx(1.0));
  CHECK((face.point - P3(0.3, 0.6, 0)).norm() < 1e-12);
  const auto edge = cube.closest_point(P3(0.5, -1, -1));
  CHECK(edge.where.kind == Kind::FeatureEdge);
  const std::int32_t e01 = cube.surface().find_edge(0, 1);
  CHECK(cube.features().feature_edges()[edge.where.feature] == e01);
  CHECK(edge.distance == Approx(std::sqrt(2.0)));
  const auto corner = cube.closest_point(P3(2, 2, 2));
  CHECK(corner.where.kind == Kind::Corner);
  CHECK(cube.features().corners()[corner.where.feature] == 6);
  // The barycentric parameters give the point back on the reported triangle.
  const Triangle& t = cube.surface().triangle(face.where.patch);
  const P3 a = cube.surface().vertex(t[0]), b = cube.surface().vertex(t[1]), c = cube.surface().vertex(t[2]);
  CHECK((a + face.where.param[0] * (b - a) + face.where.param[1] * (c - a) - face.point).norm() < 1e-12);
}

TEST_CASE("local minima inside a cube: one per face, nearest first", "[surface_boundary]") {
  const SurfaceBoundary cube = unit_cube();
  const P3 p(0.5, 0.5, 0.3);
  const auto all = cube.closest_points(p, 10);
  REQUIRE(all.size() == 6);
  const double expected[6] = {0.3, 0.5, 0.5, 0.5, 0.5, 0.7};
  for (int i = 0; i < 6; ++i) CHECK(all[i].distance == Approx(expected[i]));
  CHECK((all[0].point - cube.closest_point(p).point).norm() == 0.0);
  CHECK(cube.closest_points(p, 2).size() == 2);
}

TEST_CASE("classify, inside and segment crossing on a cube", "[surface_boundary]") {
  const SurfaceBoundary cube = unit_cube();
  CHECK(cube.classify(box(P3(0.2, 0.2, 0.2), P3(0.4, 0.4, 0.4))) == Side::In);
  CHECK(cube.classify(box(P3(2, 2, 2), P3(3, 3, 3))) == Side::Out);
  CHECK(cube.classify(box(P3(0.5, 0.5, 0.5), P3(1.5, 1.5, 1.5))) == Side::Partial);
  CHECK(cube.classify(box(P3(0.5, 0.5, 0.5), P3(1.0, 0.9, 0.9))) == Side::Partial);  // touches x = 1
  CHECK(cube.classify(box(P3(-1, -1, -1), P3(2, 2, 2))) == Side::Partial);           // holds the cube
  CHECK(cube.is_inside(P3(0.5, 0.5, 0.5)));
  CHECK_FALSE(cube.is_inside(P3(1.5, 0.5, 0.5)));
  CHECK_FALSE(cube.is_inside(P3(1.0, 0.5, 0.5)));  // on the surface: not strictly inside
  CHECK(cube.segment_crosses(P3(0.5, 0.5, 0.5), P3(1.5, 0.5, 0.5)));
  CHECK_FALSE(cube.segment_crosses(P3(0.2, 0.5, 0.5), P3(0.8, 0.5, 0.5)));
  CHECK_FALSE(cube.segment_crosses(P3(0.5, 0.5, 0.5), P3(0.5, 0.5, 0.0)));  // ends on the surface
  CHECK(cube.segment_crosses(P3(0.5, 0.5, 0.5), P3(0.5, 0.5, -0.1)));
}

TEST_CASE("inside test against the analytic sphere", "[surface_boundary][property]") {
  const SurfaceBoundary& s = data("sphere966.off");
  const P3 c = s.bounding_box().center();
  double r_max = 0.0;
  for (const P3& v : s.vertices()) r_max = std::max(r_max, (v - c).norm());
  febemesh::test::prop("clearly inside / outside agrees with |p - c| vs r", 300, [&] {
    const P3 p = c + r_max * P3(*rc::gen::inRange(-1500, 1501), *rc::gen::inRange(-1500, 1501),
                                *rc::gen::inRange(-1500, 1501)) / 1000.0;
    const double rho = (p - c).norm() / r_max;
    RC_PRE(rho < 0.9 || rho > 1.05);  // the polyhedron lies between about 0.99 r and r
    RC_ASSERT(s.is_inside(p) == (rho < 0.9));
    RC_ASSERT(s.is_inside_ref(p) == (rho < 0.9));
  });
}

TEST_CASE("ray-parity inside test equals the pseudo-normal twin on CAD parts", "[surface_boundary][property]") {
  for (const char* name : {"fandisk.off", "anchor.off", "rotor.off"}) {
    const SurfaceBoundary& s = data(name);
    const Box<3> b = s.bounding_box();
    febemesh::test::prop(std::string(name) + ": is_inside == is_inside_ref", 200, [&] {
      const P3 t(*rc::gen::inRange(0, 1001) / 1000.0, *rc::gen::inRange(0, 1001) / 1000.0,
                 *rc::gen::inRange(0, 1001) / 1000.0);
      const P3 p = b.lo + b.extent().cwiseProduct(t);
      RC_PRE(s.closest_point(p).distance > 1e-6 * b.extent().norm());
      RC_ASSERT(s.is_inside(p) == s.is_inside_ref(p));
    });
  }
}

TEST_CASE("accessors and root box", "[surface_boundary]") {
  const SurfaceBoundary& s = data("sphere966.off");
  CHECK(s.n_components() == 1);
  CHECK(s.euler_characteristic() == 2);
  const double r = 0.5 * s.bounding_box().extent().maxCoeff();
  CHECK(s.volume() == Approx(4.0 / 3.0 * M_PI * r * r * r).epsilon(0.02));
  CHECK(s.area() == Approx(4.0 * M_PI * r * r).epsilon(0.02));
  const Box<3> root = s.root_box();
  CHECK(root.extent()[0] == Approx(1.05 * s.bounding_box().extent().maxCoeff()));
  CHECK(root.extent()[0] == Approx(root.extent()[1]));
  CHECK(root.extent()[0] == Approx(root.extent()[2]));
  CHECK(root.contains(s.bounding_box().lo));
  CHECK(root.contains(s.bounding_box().hi));
}

TEST_CASE("level field: global, features, curvature, cap", "[surface_boundary]") {
  SurfaceBoundary cube = unit_cube();
  cube.set_global_level(3);
  CHECK(cube.control_level(box(P3(0.3, 0.3, 0.3), P3(0.4, 0.4, 0.4))) == 3.0);  // away from the surface
  CHECK(cube.control_level(box(P3(0.9, 0.9, -0.1), P3(1.1, 1.1, 0.1))) == 4.0);  // at a feature
  cube.set_max_level(3.5);
  CHECK(cube.control_level(box(P3(0.9, 0.9, -0.1), P3(1.1, 1.1, 0.1))) == 3.5);

  // A box on the middle of a face meets triangles that touch feature edges (every triangle of
  // the cube does): the feature level, unless SurfaceOptions::feature_level_at_edges, which asks
  // the box to meet the feature edge itself or hold a corner.
  const Box<3> mid_face = box(P3(0.45, 0.45, -0.05), P3(0.55, 0.55, 0.05));
  CHECK(cube.control_level(mid_face) == 3.5);
  {
    SurfaceOptions at_edges;
    at_edges.feature_level_at_edges = true;
    SurfaceBoundary c2(cube.surface(), at_edges);
    c2.set_global_level(3);
    CHECK(c2.control_level(mid_face) == 3.0);
    CHECK(c2.control_level(box(P3(0.9, 0.9, -0.1), P3(1.1, 1.1, 0.1))) == 4.0);  // at a corner
    CHECK(c2.control_level(box(P3(0.45, 0.95, -0.05), P3(0.55, 1.05, 0.05))) == 4.0);  // on an edge
  }

  // Sphere: a cell should span at most `arc` radians: level ~ log2(root side / (r * arc)).
  SurfaceBoundary sphere = SurfaceBoundary::from_file(std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off");
  const double r = 0.5 * sphere.bounding_box().extent().maxCoeff();
  const double expected = std::log2(sphere.root_box().extent()[0] / (r * 0.5));
  for (std::int32_t t = 0; t < sphere.surface().n_triangles(); t += 97)
    CHECK(sphere.curvature_level(t) == Approx(expected).margin(0.5));
  sphere.set_global_level(0);
  const double at_surface = sphere.control_level(sphere.bounding_box());
  CHECK(at_surface > expected - 0.5);
  CHECK(at_surface < expected + 0.5);
  const P3 c = sphere.bounding_box().center();
  CHECK(sphere.control_level(box(c.array() - 0.01 * r, c.array() + 0.01 * r)) == 0.0);
}

TEST_CASE("thickness: the thinnest of centroid and vertices along the inward normal", "[surface_boundary][thickness]") {
  // (The rays start 1e-9 of the diagonal inside, hence the tolerance.)
  // A tapered plate: bottom z = 0, top z = h0 + slope x over the unit square, end faces at
  // x = 0 (h0 thick) and x = 1 (h1). From a point (x, y, z) of the top, the ray along the top's
  // inward normal meets the bottom after z * sqrt(1 + slope^2); the thinnest is at x = 0.
  const double h0 = 0.1, h1 = 0.3, slope = h1 - h0;
  TriangleSoup soup;
  soup.vertices = {P3(0, 0, 0), P3(1, 0, 0), P3(1, 1, 0), P3(0, 1, 0),
                   P3(0, 0, h0), P3(1, 0, h1), P3(1, 1, h1), P3(0, 1, h0)};
  soup.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                    {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  Surface surface(soup);
  validate_surface(surface, "tapered plate");
  SurfaceBoundary plate(std::move(surface));
  const double top = h0 * std::sqrt(1 + slope * slope);
  CHECK(plate.thickness(2) == Approx(top).epsilon(1e-6));  // top {4, 5, 6}
  CHECK(plate.thickness(3) == Approx(top).epsilon(1e-6));  // top {4, 6, 7}
  CHECK(plate.thickness(0) == Approx(h0).epsilon(1e-6));   // bottom: its vertex at x = 0
  CHECK(plate.thickness(1) == Approx(h0).epsilon(1e-6));
  CHECK(plate.thickness(10) == Approx(1.0).epsilon(1e-6));  // end face x = 0: across to x = 1
  // The centroid alone misses the taper: top {4, 5, 6}'s centroid is at x = 2/3.
  const P3 c = (P3(0, 0, h0) + P3(1, 0, h1) + P3(1, 1, h1)) / 3.0;
  CHECK(plate.thickness_from(2, c, -1) == Approx((h0 + slope * 2.0 / 3.0) * std::sqrt(1 + slope * slope)).epsilon(1e-6));
  // From the sharp top edge at x = 1 (under 90 degrees) the ray along the end face's inward
  // normal leaves the solid at once, beside its own triangles: no thickness there.
  CHECK(std::isinf(plate.thickness_from(7, P3(1, 0, h1), 5)));  // end face {1, 6, 5}
  // The level field asks for `cells` octants across the thinnest, up to the cap.
  const double root = plate.root_box().extent()[0];
  plate.set_global_level(0);
  plate.set_thickness_level(4, 20);
  const double wanted = std::log2(root * 4 / top);
  CHECK(plate.control_level(box(P3(0.9, 0.4, 0.25), P3(0.95, 0.45, 0.32))) == Approx(wanted).epsilon(1e-6));
  plate.set_thickness_level(4, 5);
  CHECK(plate.control_level(box(P3(0.9, 0.4, 0.25), P3(0.95, 0.45, 0.32))) == 5.0);
  plate.set_thickness_level(0, 20);
  CHECK(plate.control_level(box(P3(0.9, 0.4, 0.25), P3(0.95, 0.45, 0.32))) < wanted - 1);
  // Sampled (SurfaceOptions::thickness_sampled): the level of the rays near the box, where the
  // plate is about 0.22 thick (x 0.6-0.65, the rays from x 0.55-0.7), not of the top triangle's
  // thinnest end (0.1); at that end the same.
  plate.set_thickness_sampled(true);
  plate.set_thickness_level(4, 20);
  const double near_box = plate.control_level(box(P3(0.6, 0.3, 0.2), P3(0.65, 0.35, 0.25)));
  const double stretch = std::sqrt(1 + slope * slope);
  CHECK(near_box < wanted - 1);
  CHECK(near_box > std::log2(root * 4 / ((h0 + 0.7 * slope) * stretch)));
  CHECK(near_box < std::log2(root * 4 / ((h0 + 0.55 * slope) * stretch)));
  CHECK(plate.control_level(box(P3(0.0, 0.4, 0.05), P3(0.02, 0.45, 0.12))) == Approx(wanted).epsilon(0.02));
}

TEST_CASE("a segment to the closest point on a sliver triangle does not cross the surface", "[surface_boundary]") {
  // rotor.off's outer wall is triangles 0.4 long and 0.07 wide. A lattice node of a level-8
  // interior octant lies 1e-5 inside one of them: a segment stopping 1e-7 of its length short
  // of the closest point ends 1e-12 from the plane, within orient3d's tolerance (a Degenerate
  // crossing); crosses_before stops 1e-9 of the diagonal short.
  const SurfaceBoundary& rotor = data("rotor.off");
  const P3 q(-0.0246094, -0.2912109, -0.3322266);
  REQUIRE(rotor.is_inside(q));
  const ClosestPoint<3> c = rotor.closest_point(q);
  REQUIRE(c.distance < 2e-5);
  const P3 p(c.point);
  CHECK(rotor.segment_crosses(q, q + (1.0 - 1e-7) * (p - q)));
  CHECK_FALSE(rotor.crosses_before(q, p));
  CHECK(rotor.crosses_before(q, q + 3.0 * (p - q)));  // one that leaves the solid still crosses
  CHECK_FALSE(rotor.crosses_before(q, q));
}
