// dim2/improve2d.hpp: the smallest corner angle with atan2 only near the smallest cotangent is
// the all-corners value bit for bit (the quality pass's decisions, hence the mesh, hang on it),
// on template-like shapes full of exact ties and on arbitrary ones.

#include <cmath>

#include <catch2/catch.hpp>

#include "dim2/improve2d.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

/// One element with the given corners (counter-clockwise or not).
Mesh<2> one_element(const std::vector<Point<2>>& p) {
  Mesh<2> m;
  std::vector<VertexId> v;
  for (const auto& x : p) v.push_back(m.add_point(x));
  m.solid.add(p.size() == 3 ? ElemType::Tri3 : ElemType::Quad4, v.data(), static_cast<int>(v.size()));
  return m;
}

void check_same(const std::vector<Point<2>>& p) {
  const Mesh<2> m = one_element(p);
  const double fast = min_corner_angle_deg(m, 0), ref = min_corner_angle_deg_ref(m, 0);
  RC_ASSERT(fast == ref);
}

}  // namespace

TEST_CASE("min corner angle: template shapes", "[improve]") {
  using P = Point<2>;
  const Mesh<2> right = one_element({P(0, 0), P(1, 0), P(0, 1)});
  CHECK(min_corner_angle_deg(right, 0) == min_corner_angle_deg_ref(right, 0));
  CHECK(min_corner_angle_deg(right, 0) == Approx(45.0));
  const Mesh<2> square = one_element({P(0, 0), P(2, 0), P(2, 2), P(0, 2)});
  CHECK(min_corner_angle_deg(square, 0) == min_corner_angle_deg_ref(square, 0));
  const Mesh<2> clockwise = one_element({P(0, 0), P(0, 1), P(1, 0)});
  CHECK(min_corner_angle_deg(clockwise, 0) == -1.0);
  CHECK(min_corner_angle_deg_ref(clockwise, 0) == -1.0);
}

TEST_CASE("min corner angle = its all-corners twin", "[improve][property]") {
  test::prop("lattice triangles and quads (ties)", 500, [] {
    const int n = *rc::gen::inRange(3, 5);
    const double scale = std::ldexp(1.0, *rc::gen::inRange(-12, 8));
    const Point<2> shift(*rc::gen::inRange(-1000, 1000) * 0.37, *rc::gen::inRange(-1000, 1000) * 0.11);
    std::vector<Point<2>> p;
    for (int k = 0; k < n; ++k)
      p.push_back(shift + scale * Point<2>(*rc::gen::inRange(-4, 5), *rc::gen::inRange(-4, 5)));
    check_same(p);
  });
  test::prop("arbitrary triangles and quads", 500, [] {
    const int n = *rc::gen::inRange(3, 5);
    std::vector<Point<2>> p;
    for (int k = 0; k < n; ++k)
      p.push_back(Point<2>(*rc::gen::inRange(-1000000, 1000000) * 1e-6, *rc::gen::inRange(-1000000, 1000000) * 1e-6));
    check_same(p);
  });
  test::prop("nearly isosceles triangles", 500, [] {
    const double eps = std::ldexp(1.0, -*rc::gen::inRange(20, 60));
    const double t = *rc::gen::inRange(1, 1000) * 1e-3;
    check_same({Point<2>(0, 0), Point<2>(1, 0), Point<2>(0.5 + eps * t, 0.3 + t)});
  });
}
