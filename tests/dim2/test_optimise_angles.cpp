// The corner-angle optimiser (dim2/optimise_angles): it raises the worst angle quality, never
// inverts an element, leaves locked nodes where they are and keeps sliding nodes on the curve.

#include <catch2/catch.hpp>

#include <cmath>

#include "core/validate.hpp"
#include "dim2/optimise_angles.hpp"
#include "property.hpp"

using namespace febemesh;
using namespace febemesh::dim2;

namespace {

/// An n x n grid of unit quads on [0, n]^2, every interior node displaced by (dx, dy)(node).
template <class Disp>
Mesh<2> grid(int n, Disp disp) {
  Mesh<2> m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      Point<2> p(i, j);
      if (i > 0 && j > 0 && i < n && j < n) p += disp(i, j);
      m.add_point(p);
    }
  auto id = [&](int i, int j) { return VertexId{j * (n + 1) + i}; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.solid.add(ElemType::Quad4, {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      m.level.push_back(0);
      m.from_boundary_cell.push_back(0);
    }
  return m;
}

double worst(const Mesh<2>& m) {
  double q = 1e300;
  for (std::size_t e = 0; e < m.solid.size(); ++e) q = std::min(q, angle_quality(m, e));
  return q;
}

std::vector<std::uint8_t> lock_border(const Mesh<2>& m, int n) {
  std::vector<std::uint8_t> locked(m.points.size(), 0);
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    const double x = m.points[v][0], y = m.points[v][1];
    if (x == 0 || y == 0 || x == n || y == n) locked[v] = 1;
  }
  return locked;
}

}  // namespace

TEST_CASE("angle quality measures triangles against 20 deg and quads against [30, 150]", "[optimise_angles]") {
  Mesh<2> m;
  m.add_point(Point<2>(0, 0));
  m.add_point(Point<2>(1, 0));
  m.add_point(Point<2>(1, 1));
  m.add_point(Point<2>(0, 1));
  m.solid.add(ElemType::Quad4, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}});
  m.solid.add(ElemType::Tri3, {VertexId{0}, VertexId{1}, VertexId{2}});
  CHECK(angle_quality(m, 0) == Approx(90.0 / 30.0));
  CHECK(angle_quality(m, 1) == Approx(45.0 / 20.0));
  m.points[2] = Point<2>(2, 1);  // quad angles 45, 135: 45/30
  CHECK(angle_quality(m, 0) == Approx(45.0 / 30.0));
  m.points[2] = Point<2>(0.2, 0.2);  // reflex corner at node 2
  CHECK(angle_quality(m, 0) < 0);
}

TEST_CASE("a badly placed interior node is moved until every quad is within [30, 150]", "[optimise_angles]") {
  const int n = 3;
  // Two interior nodes pushed far off: angles near 20 and 160 degrees.
  Mesh<2> m = grid(n, [](int i, int j) { return Point<2>(i == 1 && j == 1 ? 0.6 : 0.0, j == 2 && i == 2 ? -0.6 : 0.0); });
  const Mesh<2> before = m;
  const double q0 = worst(m);
  REQUIRE(q0 > 0);
  REQUIRE(q0 < 1.0);
  const std::vector<std::uint8_t> locked = lock_border(m, n);
  const AngleOptimiseStats st = optimise_angles(m, locked);
  CHECK(st.moves > 0);
  CHECK(st.worst_before == Approx(q0));
  CHECK(st.worst_after == Approx(worst(m)));
  CHECK(worst(m) >= 1.0);
  CHECK(validate<2>(m).inverted == 0);
  for (std::size_t v = 0; v < m.points.size(); ++v)
    if (locked[v]) CHECK(m.points[v] == before.points[v]);
  // Without measure_worst: the same points, no worst reported.
  Mesh<2> unmeasured = before;
  AngleOptimiseOptions ao;
  ao.measure_worst = false;
  const AngleOptimiseStats su = optimise_angles(unmeasured, locked, ao);
  CHECK(unmeasured.points == m.points);
  CHECK(su.moves == st.moves);
  CHECK(su.worst_before == 0.0);
  CHECK(su.worst_after == 0.0);
}

namespace {

/// A ring of k quads between radii 1 and 2, counter-clockwise, the inner nodes (even indices)
/// evenly spaced and the outer ones (odd) out of step by `outer_shift` x half the spacing,
/// alternately forwards and backwards (or the other way round). The outer circle's chords are
/// the interface (Line2) elements.
Mesh<2> ring(int k, double inner_shift, double outer_shift) {
  Mesh<2> m;
  for (int i = 0; i < k; ++i) {
    const double a = 2 * M_PI * i / k + (i % 2 ? inner_shift : -inner_shift) * (M_PI / k);
    const double b = 2 * M_PI * i / k + (i % 2 ? outer_shift : -outer_shift) * (M_PI / k);
    m.add_point(Point<2>(std::cos(a), std::sin(a)));
    m.add_point(Point<2>(2 * std::cos(b), 2 * std::sin(b)));
  }
  for (int i = 0; i < k; ++i) {
    const int j = (i + 1) % k;
    m.solid.add(ElemType::Quad4, {VertexId{2 * i}, VertexId{2 * i + 1}, VertexId{2 * j + 1}, VertexId{2 * j}});
    m.interface.add(ElemType::Line2, {VertexId{2 * j + 1}, VertexId{2 * i + 1}});
    m.level.push_back(0);
    m.from_boundary_cell.push_back(0);
  }
  return m;
}

/// Outer nodes bunched in pairs: spreading them along the circle improves the quads.
Mesh<2> bunched_ring(int k) { return ring(k, 0.0, 0.6); }

std::vector<std::uint8_t> outer_slides(const Mesh<2>& m) {
  std::vector<std::uint8_t> locked(m.points.size());
  for (std::size_t v = 0; v < locked.size(); ++v) locked[v] = v % 2 ? 2 : 1;
  return locked;
}

const SlideFn on_circle = [](std::int32_t, const Point<2>& p) { return Point<2>(2.0 * p.normalized()); };

/// Largest distance from the outer circle to the midpoint of an interface chord.
double worst_chord_deviation(const Mesh<2>& m) {
  double d = 0.0;
  for (std::size_t s = 0; s < m.interface.size(); ++s) {
    const VertexId* ab = m.interface.nodes(ElemId{static_cast<std::int32_t>(s)});
    d = std::max(d, 2.0 - (0.5 * (m.points[ab[0].v] + m.points[ab[1].v])).norm());
  }
  return d;
}

}  // namespace

TEST_CASE("sliding nodes stay on the curve", "[optimise_angles]") {
  Mesh<2> m = bunched_ring(16);
  REQUIRE(worst(m) > 0);
  const double q0 = worst(m);
  AngleOptimiseOptions ao;
  ao.target = 3.0;  // above the start (about 2.2): optimise every node
  optimise_angles(m, outer_slides(m), ao, on_circle);
  CHECK(worst(m) > q0);
  for (std::size_t v = 1; v < m.points.size(); v += 2) CHECK(std::abs(m.points[v].norm() - 2.0) < 1e-12);
  for (std::size_t v = 0; v < m.points.size(); v += 2) CHECK(std::abs(m.points[v].norm() - 1.0) < 1e-12);
}

TEST_CASE("with curve_distance, sliding never takes a chord farther from the curve", "[optimise_angles]") {
  // Inner nodes bunched, outer nodes even: the quads improve when the outer nodes follow the
  // inner ones, which lengthens every other chord. Unbounded, the optimiser does that; with the
  // bound (every chord is already the longest) the chords keep their distance to the circle.
  AngleOptimiseOptions ao;
  ao.target = 3.0;
  for (const int k : {8, 16, 24}) {
    Mesh<2> bounded = ring(k, 0.5, 0.0), unbounded = bounded;
    const double d0 = worst_chord_deviation(bounded), q0 = worst(bounded);
    REQUIRE(q0 > 0);
    optimise_angles(unbounded, outer_slides(unbounded), ao, on_circle);
    AngleOptimiseOptions bounded_ao = ao;
    bounded_ao.curve_distance = [](const Point<2>& p) { return std::abs(2.0 - p.norm()); };
    optimise_angles(bounded, outer_slides(bounded), bounded_ao, on_circle);
    INFO("k = " << k << ", chord deviation " << d0 << " -> " << worst_chord_deviation(bounded)
                << " (unbounded " << worst_chord_deviation(unbounded) << ")");
    CHECK(worst_chord_deviation(unbounded) > 1.05 * d0);  // the bound is what holds it
    CHECK(worst_chord_deviation(bounded) <= d0);
    CHECK(worst(bounded) >= q0);
    for (std::size_t v = 1; v < bounded.points.size(); v += 2) CHECK(std::abs(bounded.points[v].norm() - 2.0) < 1e-12);
  }
}

TEST_CASE("triangle_target makes triangles of a mixed mesh aim higher than its quads", "[optimise_angles]") {
  // Square [0, 2]^2, its side midpoints fixed, one free node X at (0.7, 1.3): three quads and
  // the upper-right quarter as two triangles X F C, X C G. Smallest triangle angle 28.3 deg
  // (q = 1.42), quads within [43.6, 136.4] (q >= 1.45): all above the quad aim 1.25.
  Mesh<2> m;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 0}, {2, 1}, {1, 2}, {0, 1}, {0.7, 1.3}})
    m.add_point(Point<2>(x, y));
  enum { A, B, C, D, E, F, G, H, X };
  m.solid.add(ElemType::Quad4, {VertexId{A}, VertexId{E}, VertexId{X}, VertexId{H}});
  m.solid.add(ElemType::Quad4, {VertexId{E}, VertexId{B}, VertexId{F}, VertexId{X}});
  m.solid.add(ElemType::Quad4, {VertexId{H}, VertexId{X}, VertexId{G}, VertexId{D}});
  m.solid.add(ElemType::Tri3, {VertexId{X}, VertexId{F}, VertexId{C}});
  m.solid.add(ElemType::Tri3, {VertexId{X}, VertexId{C}, VertexId{G}});
  std::vector<std::uint8_t> locked(m.points.size(), 1);
  locked[X] = 0;
  REQUIRE(angle_quality(m, 4) * 20.0 == Approx(28.3).margin(0.1));

  AngleOptimiseOptions ao;  // target 1.25 for every element: nothing to do
  Mesh<2> same = m;
  CHECK(optimise_angles(same, locked, ao).moves == 0);
  CHECK(same.points == m.points);

  ao.triangle_target = 1.5;  // triangles aim at 30 deg
  CHECK(optimise_angles(m, locked, ao).moves > 0);
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    INFO("element " << e << ": q " << angle_quality(m, e));
    CHECK(angle_quality(m, e) >= (m.solid.type[e] == ElemType::Tri3 ? 1.5 : 1.25));
  }
}

TEST_CASE("the optimiser never inverts an element nor lowers the worst quality", "[optimise_angles][property]") {
  febemesh::test::prop("random jiggled grids", 100, [] {
    const int n = *rc::gen::inRange(2, 6);
    const auto jiggle = *rc::gen::container<std::vector<int>>(2 * (n + 1) * (n + 1), rc::gen::inRange(-45, 46));
    Mesh<2> m = grid(n, [&](int i, int j) {
      const std::size_t k = 2 * std::size_t(j * (n + 1) + i);
      return Point<2>(jiggle[k] / 100.0, jiggle[k + 1] / 100.0);
    });
    const double q0 = worst(m);
    RC_PRE(q0 > 0);
    const Mesh<2> before = m;
    optimise_angles(m, lock_border(m, n));
    RC_ASSERT(worst(m) >= q0);
    RC_ASSERT(validate<2>(m).inverted == 0u);
    Mesh<2> again = before;  // deterministic
    optimise_angles(again, lock_border(before, n));
    RC_ASSERT(again.points == m.points);
  });
}

TEST_CASE("the worst quality reported is the mesh's own, read by blocks of elements", "[optimise_angles]") {
  // 130 x 130 quads (16,900 elements: five blocks of 4096), every node off its grid point by a
  // smooth field, the quads of rows 60-69 split into two triangles each: every element clearly
  // above the target, so the worst one is found through the largest badness of its kind.
  const int n = 130;
  const Mesh<2> quads = grid(n, [](int i, int j) {
    return Point<2>(0.06 * std::sin(0.7 * i + 1.3 * j), 0.05 * std::cos(1.1 * i - 0.4 * j));
  });
  Mesh<2> m;
  m.points = quads.points;
  for (std::size_t e = 0; e < quads.solid.size(); ++e) {
    const VertexId* v = quads.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const std::size_t row = e / n;
    if (row >= 60 && row < 70) {
      m.solid.add(ElemType::Tri3, {v[0], v[1], v[2]});
      m.solid.add(ElemType::Tri3, {v[0], v[2], v[3]});
      m.level.insert(m.level.end(), 2, 0);
      m.from_boundary_cell.insert(m.from_boundary_cell.end(), 2, 0);
    } else {
      m.solid.add(ElemType::Quad4, {v[0], v[1], v[2], v[3]});
      m.level.push_back(0);
      m.from_boundary_cell.push_back(0);
    }
  }
  const double q0 = worst(m);
  REQUIRE(q0 > 1.25 * 1.1);  // above the target with room: no node searched
  for (const int n_threads : {1, 2}) {
    Mesh<2> work = m;
    AngleOptimiseOptions ao;
    ao.n_threads = n_threads;
    const AngleOptimiseStats st = optimise_angles(work, lock_border(work, n), ao);
    CHECK(st.moves == 0);
    CHECK(st.worst_before == q0);  // exactly: the same element's angle_quality
    CHECK(st.worst_after == q0);
  }
  // A quad made the worst, in the third block: found there.
  Mesh<2> bent = m;
  bent.points[static_cast<std::size_t>(100 * (n + 1) + 40)] += Point<2>(0.3, 0.3);
  const double q1 = worst(bent);
  REQUIRE(q1 < q0);
  REQUIRE(q1 > 1.25 * 1.1);
  AngleOptimiseOptions ao;
  ao.rounds = 0;
  CHECK(optimise_angles(bent, lock_border(bent, n), ao).worst_before == q1);
}
