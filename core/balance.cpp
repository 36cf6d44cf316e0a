// 2:1 balance (the paper's one-level-difference rule) in O(n log n), without repeated sweeps.
//
// Work on the set I of internal (split) cells of the balanced tree. The tree is balanced iff for
// every internal cell p, each same-size neighbour q of p (across facets, or across facets, edges
// and corners) is itself a cell of the tree, i.e. parent(q) is internal: otherwise a child of p
// touches a leaf two levels coarser. I must contain the strict ancestors of the input leaves, and
// the rule only adds cells one level coarser than the cell that asks. So the smallest admissible I
// (and with it the coarsest balanced refinement) is the closure computed level by level, finest
// first, each level sorted and deduplicated once. The leaves are then the children of internal
// cells that are not internal, emitted in Morton order by one depth-first walk.

#include <algorithm>
#include <sstream>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/orthtree.hpp"

namespace febemesh {
namespace {

/// Key offset of one step along axis d at `level`, and a mask of axis d's bits.
template <int Dim> constexpr std::uint64_t axis_mask(int d) {
  std::uint64_t m = 0;
  for (int b = 0; b < max_level<Dim>; ++b) m |= std::uint64_t(1) << (Dim * b + d);
  return m;
}

/// Same-level neighbour of the cell with Morton key `key` at `level`, moved by `dir` (entries in
/// {-1, 0, 1}), computed on the dilated key directly; false when it leaves the root.
template <int Dim>
inline bool neighbour_key(std::uint64_t key, int level, const int* dir, std::uint64_t& out) {
  const int shift = Dim * (max_level<Dim> - level);
  std::uint64_t result = 0;
  for (int d = 0; d < Dim; ++d) {
    const std::uint64_t mask = axis_mask<Dim>(d);
    std::uint64_t x = key & mask;
    const std::uint64_t step = std::uint64_t(1) << (shift + d);
    if (dir[d] > 0) {
      // Dilated addition: set the other axes' bits so that carries propagate through them.
      x = ((x | ~mask) + step) & mask;
      if (x == 0) return false;  // wrapped past the upper root face
    } else if (dir[d] < 0) {
      if (x == 0) return false;
      x = (x - step) & mask;
    }
    result |= x;
  }
  out = result;
  return true;
}

template <int Dim> struct Directions {
  /// Does the balance kind look along directions that move on this subset of axes (bitmask)?
  /// Face: single axes only; Full: any non-empty subset (edges and corners too).
  static bool wanted(int axes, BalanceKind kind) {
    return kind == BalanceKind::Full || (axes & (axes - 1)) == 0;
  }
};

/// Refuses a balance whose output would pass the leaf limit; `at_least` when later levels would
/// add more.
template <int Dim> [[noreturn]] void refuse_balance(std::size_t n_leaves, std::size_t max_leaves, bool at_least) {
  std::ostringstream os;
  os << "2:1 balance would create " << (at_least ? "at least " : "") << n_leaves << " leaves ("
     << (at_least ? "at least " : "") << (double(n_leaves) * double(sizeof(Cell<Dim>)) / 1048576.0)
     << " MiB at " << sizeof(Cell<Dim>) << " bytes per leaf), more than max_leaves = " << max_leaves
     << "; raise the limit or refine less";
  throw LimitError(os.str());
}

}  // namespace

template <int Dim>
Orthtree<Dim> balance_2to1(const Orthtree<Dim>& t, BalanceKind kind, const BalanceOptions& opt) {
  constexpr std::size_t nc = Cube<Dim>::n_children;
  const auto& leaves = t.leaves();
  if (leaves.size() > opt.max_leaves) refuse_balance<Dim>(leaves.size(), opt.max_leaves, false);
  int deepest = 0;
  for (const auto& c : leaves) deepest = std::max(deepest, int(c.level));
  if (deepest <= 1) return t;  // children of the root are always balanced

  // internal[L]: sorted Morton keys of internal cells at level L. Parents of the leaves come out
  // sorted from the Morton-ordered leaves (masking low bits is monotone).
  std::vector<std::vector<std::uint64_t>> internal(deepest);
  for (const auto& c : leaves) {
    if (c.level == 0) continue;
    const int pl = c.level - 1;
    const std::uint64_t pk = detail::interleave<Dim>(c.anchor) & ~((std::uint64_t(1) << (Dim * (max_level<Dim> - pl))) - 1);
    auto& v = internal[pl];
    if (v.empty() || v.back() != pk) v.push_back(pk);
  }
  MESH_ASSERT(std::all_of(internal.begin(), internal.end(),
                          [](const auto& v) { return std::is_sorted(v.begin(), v.end()); }),
              "leaves are not in Morton order");

  // Every internal cell adds nc - 1 leaves; the count only grows, so a lower bound over the
  // limit can be refused before the later levels are computed.
  std::size_t n_internal = 0;
  for (const auto& v : internal) n_internal += v.size();
  const auto check_limit = [&](bool final) {
    const std::size_t n_out = 1 + n_internal * (nc - 1);
    if (n_out > opt.max_leaves) refuse_balance<Dim>(n_out, opt.max_leaves, !final);
  };
  check_limit(false);

  {
    std::vector<std::uint64_t> candidates, merged;
    for (int level = deepest - 1; level >= 1; --level) {
      const auto& here = internal[level];
      const int pl = level - 1;
      const std::uint64_t parent_mask = ~(volume_units(Cell<Dim>{{}, std::uint8_t(pl)}) - 1);
      const int child_shift = Dim * (max_level<Dim> - level);
      candidates.clear();
      // One sibling group at a time: the union of outward sides of its internal children says
      // which neighbours of the parent are required.
      for (std::size_t i = 0; i < here.size();) {
        const std::uint64_t pk = here[i] & parent_mask;
        unsigned present = 0;  // bit k: child k of the parent is internal
        for (; i < here.size() && (here[i] & parent_mask) == pk; ++i) {
          present |= 1u << ((here[i] >> child_shift) & (nc - 1));
        }
        candidates.push_back(pk);
        // A direction is a subset of axes plus a side on each; it leaves the parent only from a
        // child lying on that side along every axis of the subset.
        for (int axes = 1; axes < int(nc); ++axes) {
          if (!Directions<Dim>::wanted(axes, kind)) continue;
          for (int signs = 0; signs < int(nc); ++signs) {
            if ((signs & ~axes) != 0) continue;
            bool reachable = false;
            for (int k = 0; k < int(nc); ++k) {
              if (((present >> k) & 1u) && (k & axes) == signs) reachable = true;
            }
            if (!reachable) continue;
            int dir[Dim];
            for (int d = 0; d < Dim; ++d) dir[d] = ((axes >> d) & 1) ? (((signs >> d) & 1) ? 1 : -1) : 0;
            std::uint64_t nk;
            if (neighbour_key<Dim>(pk, pl, dir, nk)) candidates.push_back(nk);
          }
        }
      }
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      auto& below = internal[pl];
      merged.clear();
      merged.reserve(candidates.size() + below.size());
      std::set_union(candidates.begin(), candidates.end(), below.begin(), below.end(),
                     std::back_inserter(merged));
      n_internal += merged.size() - below.size();
      below.swap(merged);
      check_limit(false);
    }
  }  // the work arrays are freed before the output is allocated
  check_limit(true);

  // The walk below needs, per internal cell, only which of its children are internal: one byte
  // instead of an 8-byte key. Built top-down so that each level's keys are freed once used.
  std::vector<std::vector<std::uint8_t>> masks(deepest);
  for (int level = 0; level < deepest; ++level) {
    const auto& here = internal[level];
    auto& m = masks[level];
    m.assign(here.size(), 0);
    if (level + 1 < deepest) {
      const auto& next = internal[level + 1];
      const std::uint64_t parent_mask = ~(volume_units(Cell<Dim>{{}, std::uint8_t(level)}) - 1);
      const int child_shift = Dim * (max_level<Dim> - level - 1);
      std::size_t j = 0;
      for (const std::uint64_t key : next) {
        const std::uint64_t pk = key & parent_mask;
        while (here[j] != pk) ++j;  // every internal cell's parent is internal
        m[j] = std::uint8_t(m[j] | (1u << ((key >> child_shift) & (nc - 1))));
      }
    }
    std::vector<std::uint64_t>().swap(internal[level]);
  }

  // Children of internal cells that are not internal are the leaves; a depth-first walk meets
  // each level's internal cells in increasing key order, so one cursor per level suffices.
  std::vector<Cell<Dim>> out;
  out.reserve(1 + n_internal * (nc - 1));  // exact
  advise_huge_pages(out.data(), out.capacity() * sizeof(Cell<Dim>));
  std::vector<std::size_t> cursor(masks.size() + 1, 0);
  struct Walker {
    const std::vector<std::vector<std::uint8_t>>& masks;
    std::vector<std::size_t>& cursor;
    std::vector<Cell<Dim>>& out;
    void walk(const Cell<Dim>& p, std::size_t index) {
      const int level = p.level + 1;
      const std::uint32_t half = std::uint32_t(1) << (max_level<Dim> - level);
      const unsigned mask = masks[p.level][index];
      for (int i = 0; i < int(nc); ++i) {
        Cell<Dim> ch;
        ch.level = std::uint8_t(level);
        for (int d = 0; d < Dim; ++d) ch.anchor[d] = p.anchor[d] + (((i >> d) & 1) ? half : 0);
        if ((mask >> i) & 1u) {
          walk(ch, cursor[level]++);
        } else {
          out.push_back(ch);
        }
      }
    }
  };
  Walker{masks, cursor, out}.walk(Cell<Dim>{}, 0);
  MESH_ASSERT(out.size() == 1 + n_internal * (nc - 1),
              "balanced tree has " << out.size() << " leaves for " << n_internal << " internal cells");
  return Orthtree<Dim>(t.root_box(), std::move(out));
}

template Orthtree<2> balance_2to1<2>(const Orthtree<2>&, BalanceKind, const BalanceOptions&);
template Orthtree<3> balance_2to1<3>(const Orthtree<3>&, BalanceKind, const BalanceOptions&);

}  // namespace febemesh
