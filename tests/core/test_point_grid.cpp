// tests for core/point_grid.hpp

#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

#include "core/point_grid.hpp"

using namespace febemesh;

namespace {

/// Random points, half of them on a coarse lattice (shared coordinates, as mesh nodes have),
/// some duplicated, queried with random boxes of every size; the grid must visit exactly the
/// points inside each box, once each.
template <int Dim> void check_against_brute_force(std::uint64_t seed, bool flat, bool shell = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  const std::size_t n = 1 + rng() % 400;
  std::vector<Point<Dim>> pts(n);
  for (auto& p : pts) {
    for (int d = 0; d < Dim; ++d) p[d] = rng() % 2 ? u(rng) : std::floor(u(rng) * 8) / 8;
    if (flat) p[Dim - 1] = 0.5;
    // On a sphere (a circle in 2D): the points crowd few of the box's cells, and the grid
    // makes its cells smaller.
    if (shell && p.norm() > 0) p = Point<Dim>(p / p.norm());
  }
  for (std::size_t i = 0; i < n / 10; ++i) pts[rng() % n] = pts[rng() % n];
  std::vector<std::int32_t> ids;
  for (std::size_t i = 0; i < n; ++i)
    if (rng() % 5) ids.push_back(static_cast<std::int32_t>(i));
  const PointGrid<Dim> grid(pts, ids);
  for (int q = 0; q < 200; ++q) {
    Box<Dim> box;
    for (int d = 0; d < Dim; ++d) {
      const double c = rng() % 3 ? pts[rng() % n][d] : u(rng), h = std::exp2(-double(rng() % 12)) * (rng() % 4 ? 1 : 0);
      box.lo[d] = c - h * (rng() % 2), box.hi[d] = c + h;
    }
    std::vector<std::int32_t> got, want;
    grid.query(box, [&](std::int32_t id) { got.push_back(id); });
    for (const std::int32_t id : ids)
      if (box.contains(pts[id])) want.push_back(id);
    std::sort(got.begin(), got.end());
    REQUIRE(got == want);
  }
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("PointGrid visits exactly the points in a box", "[point_grid]", ((int Dim), Dim), 2, 3) {
  for (std::uint64_t seed = 1; seed <= 100; ++seed) check_against_brute_force<Dim>(seed, seed % 4 == 0);
  for (std::uint64_t seed = 101; seed <= 150; ++seed) check_against_brute_force<Dim>(seed, false, true);
}

TEST_CASE("PointGrid: no points, one point, non-finite coordinates", "[point_grid]") {
  std::vector<Point<2>> pts = {Point<2>(1, 1), Point<2>(std::nan(""), 0), Point<2>(1, 1)};
  Box<2> all{Point<2>(-10, -10), Point<2>(10, 10)};
  std::vector<std::int32_t> got;
  PointGrid<2>(pts, {}).query(all, [&](std::int32_t id) { got.push_back(id); });
  CHECK(got.empty());
  PointGrid<2>(pts, {0, 1, 2}).query(all, [&](std::int32_t id) { got.push_back(id); });
  CHECK(got == std::vector<std::int32_t>{0, 2});
}
