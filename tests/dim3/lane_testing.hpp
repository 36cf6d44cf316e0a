#pragma once
// What the lane kernels' bit-equality tests share (test_moving_tet.cpp, test_escobar_objective.cpp):
// a double's bits, and a small generator that gives the same numbers on every platform.

#include <cstdint>
#include <cstring>

#include "core/box.hpp"  // Point

namespace febemesh::test {

inline std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

/// A 64-bit linear congruential generator: uniform() in [-0.5, 0.5).
struct Rng {
  std::uint64_t s;
  double uniform() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53) - 0.5;
  }
  Point<3> point(double scale) { return scale * Point<3>(uniform(), uniform(), uniform()); }
};

}  // namespace febemesh::test
