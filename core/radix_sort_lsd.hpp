#pragma once
// Sorting integer keys ascending by LSD radix (11-bit digits) with a scratch buffer: the same
// sequence as std::sort, in fewer passes over memory for lists of a few hundred thousand keys.
// (core/lattice_nodes.cpp has its own: in-place MSD partitions, then LSD passes in a small
// buffer, for the boundary stage's memory peak, where no scratch buffer of the keys' size fits.)
//
// Measured (2D quality pass, the flip passes' unsure triangles and candidate edges, sorted every
// pass; NimbusSans U0067 at 10^6 triangles: 9 passes, 123,000 triangles and 369,000 edges in
// all, where std::sort was 0.9% and 0.4% of the run's samples): the stage took 0.1658 s with
// std::sort and 0.1521 s with this (flange: 0.1306 and 0.1225 with the incidence's moved lists
// too; medians of 6 and 5 alternating runs on one thread; the same meshes).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace febemesh {

/// Sorts `keys` ascending (negative keys too); `scratch` is working space (its contents are
/// lost). A digit in which all keys agree is skipped: an edge key of two node ids below 2^19
/// takes 4 passes of the 6. Fewer than 512 keys go to std::sort, whose set-up is smaller.
template <class T> void radix_sort_lsd(std::vector<T>& keys, std::vector<T>& scratch) {
  static_assert(std::is_integral_v<T> && sizeof(T) <= 8);
  using U = std::make_unsigned_t<T>;
  constexpr int bits = 11, n_digits = (8 * static_cast<int>(sizeof(T)) + bits - 1) / bits;
  constexpr std::size_t radix = std::size_t{1} << bits;
  // Signed keys with the sign bit flipped order as unsigned ones.
  constexpr U flip = std::is_signed_v<T> ? U(U{1} << (8 * sizeof(T) - 1)) : U{0};
  const std::size_t n = keys.size();
  if (n < 512 || n > std::numeric_limits<std::uint32_t>::max()) {
    std::sort(keys.begin(), keys.end());
    return;
  }
  const auto digit = [](T k, int d) {
    return static_cast<std::size_t>(((static_cast<U>(k) ^ flip) >> (d * bits)) & (radix - 1));
  };
  std::vector<std::uint32_t> count(n_digits * radix, 0);
  for (const T k : keys)
    for (int d = 0; d < n_digits; ++d) ++count[d * radix + digit(k, d)];
  scratch.resize(n);
  for (int d = 0; d < n_digits; ++d) {
    std::uint32_t* c = count.data() + d * radix;
    if (c[digit(keys[0], d)] == n) continue;  // all keys agree in this digit
    std::uint32_t start = 0;
    for (std::size_t b = 0; b < radix; ++b) start += std::exchange(c[b], start);
    for (const T k : keys) scratch[c[digit(k, d)]++] = k;
    keys.swap(scratch);
  }
}

}  // namespace febemesh
