// core/radix_sort_lsd.hpp: the same sequence as std::sort, for signed and unsigned keys of 32
// and 64 bits, short and long lists, keys that share digits (the skipped passes) and duplicates.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/radix_sort_lsd.hpp"

using namespace febemesh;

namespace {

// A deterministic generator (no dependence on the standard library's distributions).
struct Lcg {
  std::uint64_t s;
  std::uint64_t next() { return s = s * 6364136223846793005ULL + 1442695040888963407ULL; }
};

template <class T> void check_against_std_sort(std::vector<T> keys) {
  std::vector<T> expected = keys, scratch;
  std::sort(expected.begin(), expected.end());
  radix_sort_lsd(keys, scratch);
  CHECK(keys == expected);
}

}  // namespace

TEST_CASE("radix_sort_lsd gives std::sort's sequence", "[radix_sort]") {
  Lcg g{2026};
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{511}, std::size_t{512}, std::size_t{5000},
                              std::size_t{100000}}) {
    CAPTURE(n);
    std::vector<std::uint64_t> wide(n), edge(n);
    std::vector<std::int32_t> small(n), signed32(n);
    std::vector<std::int64_t> signed64(n);
    for (std::size_t i = 0; i < n; ++i) {
      wide[i] = g.next();
      // An edge key: two node ids under 2^19, so most digits are shared (skipped passes).
      const std::uint64_t a = (g.next() >> 45), b = (g.next() >> 45);
      edge[i] = (std::min(a, b) << 32) | std::max(a, b);
      small[i] = static_cast<std::int32_t>(g.next() >> 50);  // many duplicates
      signed32[i] = static_cast<std::int32_t>(g.next() >> 32);
      signed64[i] = static_cast<std::int64_t>(g.next());
    }
    check_against_std_sort(wide);
    check_against_std_sort(edge);
    check_against_std_sort(small);
    check_against_std_sort(signed32);
    check_against_std_sort(signed64);
  }
}

TEST_CASE("radix_sort_lsd keeps keys that all agree, and sorted or reversed lists", "[radix_sort]") {
  std::vector<std::uint64_t> same(3000, 0x1234567890ULL);
  check_against_std_sort(same);
  std::vector<std::int32_t> up(4000), down(4000);
  for (std::int32_t i = 0; i < 4000; ++i) up[i] = i - 2000, down[i] = 2000 - i;
  check_against_std_sort(up);
  check_against_std_sort(down);
}
