// tests for core/lattice_nodes.hpp

#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

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
