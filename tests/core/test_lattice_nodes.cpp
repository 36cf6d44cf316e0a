// tests for core/lattice_nodes.hpp

#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

#include "core/lattice_nodes.hpp"

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
