// tests for core/lattice_nodes.hpp

#include <algorithm>
#include <catch2/catch.hpp>
#include <random>
#include <utility>
#include <vector>

#include "core/lattice_nodes.hpp"
#include "core/orthtree.hpp"

using namespace febemesh;

TEST_CASE("lower_bound_from gives std::lower_bound's index from any hint", "[nodes]") {
  std::mt19937_64 rng(20261202);
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t n = rng() % 200;
    std::vector<std::uint64_t> keys(n);
    for (auto& k : keys) k = rng() % 400;
    std::sort(keys.begin(), keys.end());
    const std::uint64_t key = rng() % 410;
    const std::size_t hint = rng() % (n + 3);
    const auto expect = static_cast<std::size_t>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
    REQUIRE(lower_bound_from(keys, key, hint) == expect);
  }
}

TEMPLATE_TEST_CASE_SIG("lattice_nodes without hanging flags: the same nodes and corners", "[nodes]", ((int Dim), Dim), 2,
                       3) {
  RefineOptions opt;
  opt.max_level = Dim == 2 ? 6 : 4;
  // Refined toward the origin corner, so that the tree is graded (hanging nodes on the way).
  const auto t = balance_2to1(refine_while<Dim>(
      Orthtree<Dim>(), [](const Cell<Dim>& c) { return c.level < 2 || c.anchor[0] == 0; }, opt));
  Flags keep(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i) keep[i] = i % 7 != 3;
  const auto full = lattice_nodes(t, &keep);
  const auto lean = lattice_nodes(t, &keep, HangingFlags::Skipped);
  REQUIRE(std::count(full.hanging.begin(), full.hanging.end(), 1) > 0);
  CHECK(lean.hanging.empty());
  CHECK(lean.points == full.points);
  CHECK(lean.leaf_corners == full.leaf_corners);
}

namespace {

/// The kept leaves' corners sorted by key, once each, and each corner's index among them: what
/// lattice_nodes must give (the slow twin).
template <int Dim>
std::pair<std::vector<LatticePoint<Dim>>, std::vector<std::array<std::int32_t, Cube<Dim>::n_corners>>> nodes_by_brute_force(
    const Orthtree<Dim>& t, const Flags& keep) {
  std::vector<std::uint64_t> keys;
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    if (keep[i])
      for (int k = 0; k < Cube<Dim>::n_corners; ++k) keys.push_back(point_key<Dim>(corner(t.leaf(i), k)));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<LatticePoint<Dim>> points;
  for (const std::uint64_t k : keys) points.push_back(point_from_key<Dim>(k));
  std::vector<std::array<std::int32_t, Cube<Dim>::n_corners>> corners(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    for (int k = 0; k < Cube<Dim>::n_corners; ++k)
      corners[i][k] = keep[i] ? static_cast<std::int32_t>(std::lower_bound(keys.begin(), keys.end(), point_key<Dim>(corner(t.leaf(i), k))) - keys.begin())
                              : -1;
  return {points, corners};
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("lattice_nodes: the kept corners sorted by key, on any thread count", "[nodes]", ((int Dim), Dim), 2, 3) {
  // A wide tree (the corner keys sorted with their places packed below them: over 2^16 keys,
  // so several runs on the threads) and one refined to the finest level at a corner (keys too
  // wide for the places: sorted alone, then searched).
  RefineOptions wide;
  wide.max_level = Dim == 2 ? 8 : 6;
  const auto a = balance_2to1(refine_while<Dim>(
      Orthtree<Dim>(), [](const Cell<Dim>& c) { return c.level < (Dim == 2 ? 7 : 5) || c.anchor[1] == 0; }, wide));
  const auto b = balance_2to1(refine_while<Dim>(Orthtree<Dim>(), [](const Cell<Dim>& c) {
    bool at_origin = true;
    for (int d = 0; d < Dim; ++d) at_origin = at_origin && c.anchor[d] == 0;
    return c.level < 2 || at_origin;
  }));
  // And one refined deep inside one level-5 cell only: its keys agree in their highest varying
  // byte and more, so the sort partitions that bucket again before its LSD passes (over 2^14
  // keys in one range).
  Cell<Dim> deep;
  deep.level = 5;
  for (int d = 0; d < Dim; ++d) deep.anchor[d] = 11u * length(deep);
  const auto c = balance_2to1(refine_while<Dim>(Orthtree<Dim>(), [&](const Cell<Dim>& x) {
    bool overlaps = true;
    for (int d = 0; d < Dim; ++d)
      overlaps = overlaps && x.anchor[d] < deep.anchor[d] + length(deep) && deep.anchor[d] < x.anchor[d] + length(x);
    return x.level < 3 || (overlaps && x.level < (Dim == 2 ? 12 : 9));
  }));
  REQUIRE(a.n_leaves() * Cube<Dim>::n_corners > (std::size_t(1) << 16));
  REQUIRE(b.leaf(0).level == max_level<Dim>);
  REQUIRE(c.n_leaves() * Cube<Dim>::n_corners > (std::size_t(1) << 15));
  for (const Orthtree<Dim>* t : {&a, &b, &c}) {
    Flags keep(t->n_leaves());
    for (std::size_t i = 0; i < t->n_leaves(); ++i) keep[i] = i % 5 != 2;
    const auto [points, corners] = nodes_by_brute_force(*t, keep);
    for (const int threads : {1, 2, 3}) {
      INFO(t->n_leaves() << " leaves, " << threads << " threads");
      const LatticeNodes<Dim> lean = lattice_nodes(*t, &keep, HangingFlags::Skipped, threads);
      CHECK(lean.points == points);
      CHECK(lean.leaf_corners == corners);
      const LatticeNodes<Dim> full = lattice_nodes(*t, &keep, HangingFlags::Computed, threads);
      CHECK(full.points == points);
      CHECK(full.leaf_corners == corners);
      CHECK(full.hanging.size() == points.size());
    }
  }
}
