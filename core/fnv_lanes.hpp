#pragma once
// FNV-1a over a sequence of 64-bit values in four interleaved lanes, folded together at the end:
// a check that a large array is unchanged (the same values in the same order), not a
// cryptographic hash. The lanes let the multiplies overlap: the tetrahedra's hash of the
// template rounds was 0.62-0.65% of fandisk L5's samples with them, 0.77-0.79% with one chain
// (perf, one thread).

#include <cstdint>

namespace febemesh {

class FnvLanes {
 public:
  /// Mixes v into the first lane, which then goes last (the lanes stay in registers in a loop).
  void add(std::uint64_t v) {
    const std::uint64_t x = mixed(h_[0], v);
    h_[0] = h_[1], h_[1] = h_[2], h_[2] = h_[3], h_[3] = x;
  }
  std::uint64_t value() const {
    std::uint64_t out = 0;
    for (const std::uint64_t x : h_) out = mixed(out, x);
    return out;
  }

 private:
  static std::uint64_t mixed(std::uint64_t h, std::uint64_t v) { return (h ^ v) * 1099511628211ull; }
  std::uint64_t h_[4] = {1469598103934665603ull, 1469598103934665603ull ^ 1, 1469598103934665603ull ^ 2,
                         1469598103934665603ull ^ 3};
};

}  // namespace febemesh
