#pragma once
// Order of evaluation in the move guards (smoothing, the 2D quality pass): a move is rejected
// by the first incident element that fails, and the element that held the minimum before the
// move is the likeliest to fail, so it goes first and the others follow in their order.

#include <cstddef>

namespace febemesh {

/// Index of the element to evaluate j-th (j = 0, 1, ...) when the one at `worst` goes first.
constexpr std::size_t worst_first(std::size_t j, std::size_t worst) {
  return j == 0 ? worst : (j <= worst ? j - 1 : j);
}

}  // namespace febemesh
