// core/incidence_csr.hpp: the node -> item lists list each node's items ascending, once per
// listing, the same lists on any thread count.

#include <catch2/catch.hpp>

#include <cstdint>
#include <vector>

#include "core/incidence_csr.hpp"

using namespace febemesh;

TEST_CASE("incidence_csr lists each node's items in order on any thread count", "[incidence_csr]") {
  // Items of 1..4 nodes from a deterministic generator (repeats within an item too), enough of
  // them for the parts to run on several threads.
  const std::size_t n = 5000, n_items = 100000;
  std::vector<std::vector<std::int32_t>> items(n_items);
  std::uint64_t s = 12345;
  for (auto& it : items) {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    const int k = 1 + static_cast<int>((s >> 40) % 4);
    for (int i = 0; i < k; ++i) {
      s = s * 6364136223846793005ULL + 1442695040888963407ULL;
      it.push_back(static_cast<std::int32_t>((s >> 33) % n));
    }
  }
  std::vector<std::vector<std::int32_t>> expected(n);
  for (std::size_t k = 0; k < n_items; ++k)
    for (const std::int32_t v : items[k]) expected[static_cast<std::size_t>(v)].push_back(static_cast<std::int32_t>(k));
  for (const int threads : {1, 2, 3, 4}) {
    std::vector<std::int32_t> start, item;
    incidence_csr(
        n, n_items,
        [&](std::size_t k, auto&& f) {
          for (const std::int32_t v : items[k]) f(v);
        },
        threads, start, item);
    CAPTURE(threads);
    REQUIRE(start.size() == n + 1);
    for (std::size_t v = 0; v < n; ++v)
      REQUIRE(std::vector<std::int32_t>(item.begin() + start[v], item.begin() + start[v + 1]) == expected[v]);
  }
}
