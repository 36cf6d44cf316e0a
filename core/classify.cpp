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
    run_children(c, lo, hi);
  }
  /// run's descent below a cell `c` found Partial, over the leaves [lo, hi) inside it.
  void run_children(const Cell<Dim>& c, std::size_t lo, std::size_t hi) const {
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

// A leaf's answer is a function of its cell alone: the first of its ancestors (from the root)
// that b finds IN or OUT gives it, else its own box's answer; which cells are asked does not
// depend on the rest of the tree. A leaf of `before` kept in t keeps its answer; the leaves of t
// inside a leaf P of `before` take P's answer when it is IN or OUT (an ancestor, or P itself, gave
// it); inside a Partial P (every ancestor Partial, and P itself) the descent continues below P.
template <int Dim>
std::vector<Side> classify_refined(const Orthtree<Dim>& t, const Orthtree<Dim>& before, const std::vector<Side>& before_sides,
                                   const Boundary<Dim>& b, int n_threads) {
  if (before_sides.size() != before.n_leaves() || before.n_leaves() == 0 || !(t.root_box().lo == before.root_box().lo) ||
      !(t.root_box().hi == before.root_box().hi))
    return classify(t, b, n_threads);
  const auto& L = t.leaves();
  const auto& B = before.leaves();
  std::vector<Side> sides(L.size(), Side::Partial);
  struct Below {
    Cell<Dim> cell;  ///< a Partial leaf of `before`
    std::size_t lo, hi;  ///< the leaves of t inside it
  };
  std::vector<Below> below;
  std::size_t j = 0;
  for (std::size_t i = 0; i < L.size();) {
    const std::uint64_t key = morton_key(L[i]);
    while (j + 1 < B.size() && morton_key(B[j + 1]) <= key) ++j;
    const Cell<Dim>& p = B[j];
    if (p == L[i]) {
      sides[i] = before_sides[j];
      ++i;
      continue;
    }
    if (!is_ancestor(p, L[i])) return classify(t, b, n_threads);  // t is not a refinement of `before`
    const std::uint64_t end_key = morton_key(p) + volume_units(p);
    std::size_t hi = i + 1;
    while (hi < L.size() && morton_key(L[hi]) < end_key) ++hi;
    if (before_sides[j] != Side::Partial)
      std::fill(sides.begin() + std::ptrdiff_t(i), sides.begin() + std::ptrdiff_t(hi), before_sides[j]);
    else
      below.push_back({p, i, hi});
    i = hi;
  }
  for_each_range(below.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    const TopDown<Dim> walk{t, b, sides, 0, L.size()};  // each writes the leaves inside its cell only
    for (std::size_t k = begin; k < end; ++k) walk.run_children(below[k].cell, below[k].lo, below[k].hi);
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
template std::vector<Side> classify_refined<2>(const Orthtree<2>&, const Orthtree<2>&, const std::vector<Side>&,
                                                const Boundary<2>&, int);
template std::vector<Side> classify_refined<3>(const Orthtree<3>&, const Orthtree<3>&, const std::vector<Side>&,
                                                const Boundary<3>&, int);
template std::vector<Side> classify_ref<2>(const Orthtree<2>&, const Boundary<2>&);
template std::vector<Side> classify_ref<3>(const Orthtree<3>&, const Boundary<3>&);

}  // namespace febemesh
