// core/quality.hpp: Verdict measures on shapes whose values are known.

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "core/quality.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

namespace {
template <int Dim> ElementQuality q_of(ElemType t, std::vector<Point<Dim>> p) { return element_quality<Dim>(t, {p.data(), p.size()}); }
}  // namespace

TEST_CASE("triangles: equilateral and right isosceles", "[quality]") {
  using P = Point<2>;
  const auto eq = q_of<2>(ElemType::Tri3, {P(0, 0), P(1, 0), P(0.5, std::sqrt(3.0) / 2)});
  CHECK(eq.min_angle_deg == Approx(60.0));
  CHECK(eq.max_angle_deg == Approx(60.0));
  CHECK(eq.scaled_jacobian == Approx(1.0));
  CHECK(eq.aspect_ratio == Approx(1.0));

  const auto right = q_of<2>(ElemType::Tri3, {P(0, 0), P(1, 0), P(0, 1)});
  CHECK(right.min_angle_deg == Approx(45.0));
  CHECK(right.max_angle_deg == Approx(90.0));
  CHECK(right.scaled_jacobian == Approx(std::sin(M_PI / 4) * 2 / std::sqrt(3.0)));
  // Verdict aspect ratio: l_max (l0 + l1 + l2) / (4 sqrt(3) A).
  CHECK(right.aspect_ratio == Approx(std::sqrt(2.0) * (2 + std::sqrt(2.0)) / (4 * std::sqrt(3.0) * 0.5)));

  const auto inverted = q_of<2>(ElemType::Tri3, {P(0, 0), P(0.5, std::sqrt(3.0) / 2), P(1, 0)});
  CHECK(inverted.scaled_jacobian == Approx(-1.0));
  // The same triangle in 3D (an interface element) is measured unsigned.
  using Q = Point<3>;
  CHECK(q_of<3>(ElemType::Tri3, {Q(0, 0, 0), Q(0, 1, 0), Q(1, 0, 0)}).min_angle_deg == Approx(45.0));
}

TEST_CASE("quads: square, rectangle, non-convex", "[quality]") {
  using P = Point<2>;
  const auto sq = q_of<2>(ElemType::Quad4, {P(0, 0), P(1, 0), P(1, 1), P(0, 1)});
  CHECK(sq.scaled_jacobian == Approx(1.0));
  CHECK(sq.min_angle_deg == Approx(90.0));
  CHECK(sq.max_angle_deg == Approx(90.0));
  CHECK(sq.aspect_ratio == Approx(1.0));
  const auto rect = q_of<2>(ElemType::Quad4, {P(0, 0), P(2, 0), P(2, 1), P(0, 1)});
  CHECK(rect.scaled_jacobian == Approx(1.0));
  CHECK(rect.aspect_ratio == Approx(2.0 * 6.0 / (4.0 * 2.0)));
  std::vector<P> dart = {P(0, 0), P(2, 0), P(0.5, 0.5), P(0, 2)};
  CHECK(scaled_jacobian<2>(ElemType::Quad4, {dart.data(), 4}) < 0.0);
  CHECK(min_corner_jacobian<2>(ElemType::Quad4, {dart.data(), 4}) < 0.0);
  CHECK(signed_measure<2>(ElemType::Quad4, {dart.data(), 4}) == Approx(1.0));
}

TEST_CASE("tets: regular, right corner, sliver", "[quality]") {
  using P = Point<3>;
  const auto reg = q_of<3>(ElemType::Tet4, {P(1, 1, 1), P(-1, 1, -1), P(1, -1, -1), P(-1, -1, 1)});
  CHECK(reg.min_angle_deg == Approx(std::acos(1.0 / 3.0) * 180 / M_PI));  // 70.5288
  CHECK(reg.max_angle_deg == Approx(70.528779));
  CHECK(reg.scaled_jacobian == Approx(1.0));
  CHECK(reg.radius_ratio == Approx(1.0));
  CHECK(reg.aspect_ratio == Approx(1.0));

  const auto corner = q_of<3>(ElemType::Tet4, {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0, 0, 1)});
  CHECK(corner.min_angle_deg == Approx(54.7356).epsilon(1e-4));
  CHECK(corner.max_angle_deg == Approx(90.0));
  CHECK(corner.scaled_jacobian == Approx(std::sqrt(2.0) / 2));  // corner 1: J / (1 sqrt2 sqrt2)
  CHECK(corner.radius_ratio > 1.0);

  const auto sliver = q_of<3>(ElemType::Tet4, {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0.5, 0.5, 0.01)});
  CHECK(sliver.min_angle_deg < 5.0);
  CHECK(sliver.max_angle_deg > 170.0);
  CHECK(sliver.radius_ratio > 10.0);
}

TEST_CASE("hex, prism, pyramid", "[quality]") {
  using P = Point<3>;
  const auto hex = q_of<3>(ElemType::Hex8, {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1)});
  CHECK(hex.scaled_jacobian == Approx(1.0));
  CHECK(hex.min_angle_deg == Approx(90.0));
  CHECK(hex.max_angle_deg == Approx(90.0));
  CHECK(hex.aspect_ratio == Approx(1.0));
  const double h = std::sqrt(3.0) / 2;
  const auto prism = q_of<3>(ElemType::Prism6, {P(0, 0, 0), P(1, 0, 0), P(0.5, h, 0), P(0, 0, 1), P(1, 0, 1), P(0.5, h, 1)});
  CHECK(prism.scaled_jacobian == Approx(1.0));
  CHECK(prism.min_angle_deg == Approx(60.0));
  CHECK(prism.max_angle_deg == Approx(90.0));
  const auto pyr = q_of<3>(ElemType::Pyramid5, {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0.5, 0.5, std::sqrt(0.5))});
  CHECK(pyr.scaled_jacobian == Approx(1.0));
  std::vector<P> pv = {P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0.5, 0.5, 3)};
  CHECK(signed_measure<3>(ElemType::Pyramid5, {pv.data(), 5}) == Approx(1.0));
}

TEMPLATE_TEST_CASE_SIG("summary of a structured grid", "[quality]", ((int Dim), Dim), 2, 3) {
  for (const bool simplices : {false, true}) {
    const Mesh<Dim> mesh = test::grid_mesh<Dim>(3, simplices, 0.5);
    const QualitySummary s = summarize_quality(mesh);
    const double volume = std::pow(1.5, Dim);
    CHECK(s.n_elements == mesh.solid.size());
    CHECK(s.measure == Approx(volume));
    CHECK(solid_measure(mesh) == Approx(volume));
    CHECK(interface_enclosed_measure(mesh) == Approx(volume));
    std::size_t total = 0;
    for (auto c : s.scaled_jacobian_histogram) total += c;
    CHECK(total == mesh.solid.size());
    CHECK(s.min_scaled_jacobian > 0.0);
    CHECK(s.n_slivers == 0);
    if (!simplices) {
      CHECK(s.min_scaled_jacobian == Approx(1.0));
      CHECK(s.scaled_jacobian_histogram[9] == mesh.solid.size());
      CHECK(s.min_angle_deg == Approx(90.0));
    }
    CHECK(scaled_jacobians<Dim>(mesh.solid, mesh.points).size() == mesh.solid.size());
  }
}

TEST_CASE("slivers are counted below the dihedral threshold", "[quality]") {
  Mesh<3> m;
  using P = Point<3>;
  for (const P& p : {P(0, 0, 0), P(1, 0, 0), P(0, 1, 0), P(0.5, 0.5, 0.01)}) m.add_point(p);
  m.solid.add(ElemType::Tet4, {VertexId{0}, VertexId{1}, VertexId{2}, VertexId{3}});
  CHECK(summarize_quality(m, 10.0).n_slivers == 1);
  CHECK(summarize_quality(m, 0.1).n_slivers == 0);
}

TEST_CASE("the summary is the same on 1, 2 and 3 threads and sums what its elements give", "[quality][threads]") {
  // 16^3 cells, six tets each: 24576 tets, two of the summary's fixed chunks. Nodes moved off the
  // grid so that the scaled Jacobians and volumes differ from element to element.
  Mesh<3> m = test::grid_mesh<3>(16, true);
  for (Point<3>& p : m.points) p += 0.2 * Point<3>(std::sin(7.0 * p.y()), std::cos(5.0 * p.z()), std::sin(3.0 * p.x()));
  const QualitySummary one = summarize_quality(m, 40.0, 1);
  for (const int threads : {2, 3}) {
    const QualitySummary s = summarize_quality(m, 40.0, threads);
    CAPTURE(threads);
    CHECK(s.mean_scaled_jacobian == one.mean_scaled_jacobian);  // bit for bit
    CHECK(s.measure == one.measure);
    CHECK(s.min_scaled_jacobian == one.min_scaled_jacobian);
    CHECK(s.min_angle_deg == one.min_angle_deg);
    CHECK(s.max_angle_deg == one.max_angle_deg);
    CHECK(s.max_aspect_ratio == one.max_aspect_ratio);
    CHECK(s.max_radius_ratio == one.max_radius_ratio);
    CHECK(s.scaled_jacobian_histogram == one.scaled_jacobian_histogram);
    CHECK(s.n_slivers == one.n_slivers);
  }
  // Against the elements one by one.
  const std::vector<double> sj = scaled_jacobians<3>(m.solid, m.points);
  double sum = 0.0, lo = 2.0;
  std::size_t slivers = 0;
  for (std::size_t e = 0; e < sj.size(); ++e) {
    sum += sj[e], lo = std::min(lo, sj[e]);
    const auto ep = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
    slivers += element_quality<3>(ElemType::Tet4, ep.span()).min_angle_deg < 40.0 ? 1 : 0;
  }
  CHECK(one.n_elements == sj.size());
  CHECK(one.mean_scaled_jacobian == Approx(sum / static_cast<double>(sj.size())).epsilon(1e-12));
  CHECK(one.min_scaled_jacobian == lo);
  CHECK(one.measure == Approx(solid_measure<3>(m)).epsilon(1e-12));
  CHECK(one.n_slivers == slivers);
  CHECK(slivers > 0);
  CHECK(slivers < sj.size());
}

TEST_CASE("the tetrahedra's summary equals element_quality's, bit for bit", "[quality]") {
  // summarize_quality takes acos only near the extremes and the sliver threshold; element_quality
  // takes it for every dihedral angle (the slow twin).
  Mesh<3> m = test::grid_mesh<3>(8, true);
  for (Point<3>& p : m.points) p += 0.2 * Point<3>(std::sin(7.0 * p.y()), std::cos(5.0 * p.z()), std::sin(3.0 * p.x()));
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, aspect = 0.0, radius = 0.0;
  std::vector<double> mins;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const auto ep = element_points<3>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
    const ElementQuality q = element_quality<3>(ElemType::Tet4, ep.span());
    lo = std::min(lo, q.min_angle_deg), hi = std::max(hi, q.max_angle_deg);
    aspect = std::max(aspect, q.aspect_ratio), radius = std::max(radius, q.radius_ratio);
    mins.push_back(q.min_angle_deg);
  }
  std::sort(mins.begin(), mins.end());
  // Thresholds at elements' own min dihedral angles (the strict "<" at its edge) and between.
  for (const double th : {10.0, 40.0, mins[mins.size() / 3], mins[mins.size() / 2], std::nextafter(mins[7], 0.0), 179.0}) {
    const QualitySummary s = summarize_quality(m, th);
    CAPTURE(th);
    CHECK(s.min_angle_deg == lo);
    CHECK(s.max_angle_deg == hi);
    CHECK(s.max_aspect_ratio == aspect);
    CHECK(s.max_radius_ratio == radius);
    CHECK(s.n_slivers == static_cast<std::size_t>(std::lower_bound(mins.begin(), mins.end(), th) - mins.begin()));
  }
}

TEST_CASE("the triangles' and quads' summary equals element_quality's, bit for bit", "[quality]") {
  // summarize_quality takes acos only near the extremes and the sliver threshold; element_quality
  // takes it at every corner (the slow twin). Triangles, quads, both in one mesh; a quad with a
  // zero edge (its corners there count 0 deg), and a node that is not a number (the element goes
  // the generic way).
  const auto check = [](Mesh<2> m) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, aspect = 0.0, sj_lo = 2.0, measure = 0.0;
    std::vector<double> mins;
    for (std::size_t e = 0; e < m.solid.size(); ++e) {
      const auto ep = element_points<2>(m.solid, ElemId{static_cast<std::int32_t>(e)}, m.points);
      const ElementQuality q = element_quality<2>(m.solid.type[e], ep.span());
      lo = std::min(lo, q.min_angle_deg), hi = std::max(hi, q.max_angle_deg);
      aspect = std::max(aspect, q.aspect_ratio), sj_lo = std::min(sj_lo, q.scaled_jacobian);
      measure += signed_measure<2>(m.solid.type[e], ep.span());
      mins.push_back(q.min_angle_deg);
    }
    std::sort(mins.begin(), mins.end());
    // Thresholds at elements' own smallest angles (the strict "<" at its edge) and between.
    for (const double th : {10.0, 40.0, mins[mins.size() / 3], mins[mins.size() / 2], std::nextafter(mins[7], 0.0), 179.0, 0.0}) {
      const QualitySummary s = summarize_quality(m, th);
      CAPTURE(m.solid.size(), th);
      CHECK(s.min_angle_deg == lo);
      CHECK(s.max_angle_deg == hi);
      CHECK(s.max_aspect_ratio == aspect);
      CHECK(s.min_scaled_jacobian == sj_lo);
      CHECK(s.measure == measure);
      CHECK(s.n_slivers == static_cast<std::size_t>(std::lower_bound(mins.begin(), mins.end(), th) - mins.begin()));
    }
  };
  const auto wobble = [](Mesh<2> m) {
    for (Point<2>& p : m.points) p += 0.2 * Point<2>(std::sin(7.0 * p.y()), std::cos(5.0 * p.x()));
    return m;
  };
  check(wobble(test::grid_mesh<2>(40, true)));
  check(wobble(test::grid_mesh<2>(40, false)));
  Mesh<2> both = wobble(test::grid_mesh<2>(30, false));
  Elements mixed;
  for (std::size_t e = 0; e < both.solid.size(); ++e) {
    const VertexId* v = both.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    if (e % 3 == 0) {
      const std::array<VertexId, 3> a = {v[0], v[1], v[2]}, b = {v[0], v[2], v[3]};
      mixed.add(ElemType::Tri3, a.data(), 3);
      mixed.add(ElemType::Tri3, b.data(), 3);
    } else {
      mixed.add(ElemType::Quad4, v, 4);
    }
  }
  both.solid = mixed;
  both.level.clear();
  both.from_boundary_cell.clear();
  check(both);
  Mesh<2> odd = both;
  odd.points[odd.solid.node[odd.solid.offset[5] + 1].v] = odd.points[odd.solid.node[odd.solid.offset[5]].v];  // a zero edge
  check(odd);
  odd.points[odd.solid.node[odd.solid.offset[40]].v].x() = std::numeric_limits<double>::quiet_NaN();
  const QualitySummary s = summarize_quality(odd, 30.0);
  double lo = std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < odd.solid.size(); ++e) {
    const auto ep = element_points<2>(odd.solid, ElemId{static_cast<std::int32_t>(e)}, odd.points);
    lo = std::min(lo, element_quality<2>(odd.solid.type[e], ep.span()).min_angle_deg);
  }
  CHECK(s.min_angle_deg == lo);
}

TEST_CASE("a tetrahedron's min corner Jacobian is its four corners', bit for bit", "[quality]") {
  // The slow twin: each corner (c; a, b, d) of Gmsh's right-handed order, J = (a - c) . ((b - c) x (d - c)),
  // the minimum taken from infinity (a NaN corner is passed over).
  constexpr int corner[4][4] = {{0, 1, 2, 3}, {1, 2, 0, 3}, {2, 0, 1, 3}, {3, 0, 2, 1}};
  const auto reference = [&](const std::array<Point<3>, 4>& p) {
    double m = std::numeric_limits<double>::infinity();
    for (const auto& k : corner)
      m = std::min(m, (p[k[1]] - p[k[0]]).dot((p[k[2]] - p[k[0]]).cross(p[k[3]] - p[k[0]])));
    return m;
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    std::array<Point<3>, 4> p;
    for (auto& x : p) x = Point<3>(u(rng), u(rng), u(rng));
    if (i % 7 == 0) p[3] = 0.5 * (p[0] + p[1]);  // degenerate
    if (i % 11 == 0) p[2] = p[1] + Point<3>::Constant(1e-300);
    if (i % 13 == 0) p[1][0] = std::nan("");
    const double got = min_corner_jacobian<3>(ElemType::Tet4, {p.data(), 4});
    const double want = reference(p);
    CHECK(std::bit_cast<std::uint64_t>(got) == std::bit_cast<std::uint64_t>(want));
    CHECK(std::bit_cast<std::uint64_t>(jacobians<3>(ElemType::Tet4, {p.data(), 4}).first) ==
          std::bit_cast<std::uint64_t>(want));
  }
}

TEST_CASE("tet_jacobians_n gives jacobians() of each tetrahedron, bit for bit", "[quality]") {
  // Four at a time in vector lanes where the CPU has AVX, the rest one by one: random
  // tetrahedra of either orientation, flat ones, coincident points, tiny and huge scales, and
  // NaN coordinates, at every count 0..9 so that every tail length is met.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Point<3>> p;
  for (int i = 0; i < 4 * 4003; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  for (std::size_t t = 0; 4 * t + 3 < p.size(); ++t) {
    Point<3>* q = p.data() + 4 * t;
    if (t % 7 == 0) q[3] = 0.5 * (q[0] + q[1]);  // flat
    if (t % 11 == 0) q[2] = q[1];                // a zero edge
    if (t % 13 == 0) q[1][0] = std::nan("");
    if (t % 17 == 0) q[0] *= 1e-150, q[1] *= 1e-150, q[2] *= 1e-150, q[3] *= 1e-150;
    if (t % 19 == 0) q[0] *= 1e150;
  }
  const std::size_t n = p.size() / 4;
  for (const std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(3), std::size_t(4), std::size_t(5),
                                  std::size_t(8), std::size_t(9), n}) {
    std::vector<double> jac(count), scaled(count);
    tet_jacobians_n(p.data(), count, jac.data(), scaled.data());
    std::size_t same = 0;
    for (std::size_t t = 0; t < count; ++t) {
      const auto [j, s] = jacobians<3>(ElemType::Tet4, {p.data() + 4 * t, 4});
      same += std::bit_cast<std::uint64_t>(jac[t]) == std::bit_cast<std::uint64_t>(j) &&
              std::bit_cast<std::uint64_t>(scaled[t]) == std::bit_cast<std::uint64_t>(s);
    }
    CAPTURE(count);
    CHECK(same == count);
  }
}

TEST_CASE("a tetrahedron's signed volume is its facets' divergence sum, bit for bit", "[quality]") {
  // The slow twin: the sum over the four facets ({0,2,1}, {0,1,3}, {0,3,2}, {3,1,2}) of
  // (a - p0) . ((b - p0) x (c - p0)), from 0, over 6; the three through node 0 add zeros.
  constexpr int facet[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {3, 1, 2}};
  const auto reference = [&](const std::array<Point<3>, 4>& p) {
    double v = 0.0;
    for (const auto& l : facet) {
      double w = 0.0;
      w += (p[l[0]] - p[0]).dot((p[l[1]] - p[0]).cross(p[l[2]] - p[0]));
      v += w;
    }
    return v / 6.0;
  };
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::size_t same = 0, n = 0, nan = 0;
  for (int i = 0; i < 5000; ++i) {
    std::array<Point<3>, 4> p;
    for (auto& x : p) x = Point<3>(u(rng), u(rng), u(rng));
    if (i % 7 == 0) p[3] = 0.5 * (p[0] + p[1]);           // flat: a zero of either sign
    if (i % 11 == 0) p[2] = p[1];                         // a zero edge
    if (i % 13 == 0) p[1][0] = std::nan("");
    if (i % 17 == 0) for (auto& x : p) x *= 1e-150;       // tiny
    if (i % 19 == 0) for (auto& x : p) x *= 1e120;        // products overflow: the loop
    if (i % 23 == 0) p[2][1] = 1e200;                     // one huge coordinate
    if (i % 29 == 0) p[3] = p[0];                         // node 3 on node 0
    const double got = signed_measure<3>(ElemType::Tet4, {p.data(), 4});
    const double want = reference(p);
    ++n;
    if (std::isnan(want)) nan += std::isnan(got);
    else same += std::bit_cast<std::uint64_t>(got) == std::bit_cast<std::uint64_t>(want);
  }
  CHECK(same + nan == n);
}
