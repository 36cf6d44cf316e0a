// IN / OUT / PARTIAL of every leaf (paper, "Find interior quadrants"). Each leaf's answer depends
// only on its own box, so threads take contiguous ranges and write disjoint slots: the result is
// the same for any thread count.

#include "core/orthtree.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

template <int Dim>
std::vector<Side> classify(const Orthtree<Dim>& t, const Boundary<Dim>& b, int n_threads) {
  std::vector<Side> sides(t.n_leaves(), Side::Partial);
  const auto run = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sides[i] = b.classify(geometry(t, t.leaf(i)));
  };
  for_each_range(t.n_leaves(), n_threads, run);
  return sides;
}

template std::vector<Side> classify<2>(const Orthtree<2>&, const Boundary<2>&, int);
template std::vector<Side> classify<3>(const Orthtree<3>&, const Boundary<3>&, int);

}  // namespace febemesh
