// IN / OUT / PARTIAL of every leaf (paper, "Find interior quadrants"), top-down: a cell the
// boundary does not meet is IN or OUT as a whole, and its leaves take its answer without being
// asked one by one; only cells the boundary meets are split. Boundary::classify must then be
// monotone (a box inside a box the boundary misses is missed too) and is_inside constant on a
// box the boundary misses, which both dimensions' boundaries are; classify_ref asks every leaf.
// Which cells are asked depends on the whole tree only, not on a thread's range: every thread
// walks from the root and writes only its own leaves, so the result is the same for any count.

#include <algorithm>

#include "core/orthtree.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {
namespace {

template <int Dim> struct TopDown {
  const Orthtree<Dim>& t;
  const Boundary<Dim>& b;
  std::vector<Side>& sides;
  std::size_t begin, end;  // the leaves this thread writes

  /// Leaves [lo, hi) are those inside `c`.
  void run(const Cell<Dim>& c, std::size_t lo, std::size_t hi) const {
    if (lo == hi || hi <= begin || lo >= end) return;
    if (hi - lo == 1) {
      sides[lo] = b.classify(geometry(t, t.leaf(lo)));
      return;
    }
    const Side s = b.classify(geometry(t, c));
    if (s != Side::Partial) {
      std::fill(sides.begin() + std::ptrdiff_t(std::max(lo, begin)), sides.begin() + std::ptrdiff_t(std::min(hi, end)), s);
      return;
    }
    const auto& L = t.leaves();
    std::size_t first = lo;
    for (int k = 0; k < Cube<Dim>::n_children; ++k) {
      const Cell<Dim> ch = child(c, k);
      const std::uint64_t next = morton_key(ch) + volume_units(ch);
      const std::size_t last =
          k + 1 == Cube<Dim>::n_children
              ? hi
              : std::size_t(std::partition_point(L.begin() + std::ptrdiff_t(first), L.begin() + std::ptrdiff_t(hi),
                                                 [next](const Cell<Dim>& x) { return morton_key(x) < next; }) -
                            L.begin());
      run(ch, first, last);
      first = last;
    }
  }
};

}  // namespace

template <int Dim>
std::vector<Side> classify(const Orthtree<Dim>& t, const Boundary<Dim>& b, int n_threads) {
  std::vector<Side> sides(t.n_leaves(), Side::Partial);
  for_each_range(t.n_leaves(), n_threads, [&](std::size_t begin, std::size_t end) {
    TopDown<Dim>{t, b, sides, begin, end}.run(Cell<Dim>{}, 0, t.n_leaves());
  });
  return sides;
}

template <int Dim>
std::vector<Side> classify_ref(const Orthtree<Dim>& t, const Boundary<Dim>& b) {
  std::vector<Side> sides(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i) sides[i] = b.classify(geometry(t, t.leaf(i)));
  return sides;
}

template std::vector<Side> classify<2>(const Orthtree<2>&, const Boundary<2>&, int);
template std::vector<Side> classify<3>(const Orthtree<3>&, const Boundary<3>&, int);
template std::vector<Side> classify_ref<2>(const Orthtree<2>&, const Boundary<2>&);
template std::vector<Side> classify_ref<3>(const Orthtree<3>&, const Boundary<3>&);

}  // namespace febemesh
