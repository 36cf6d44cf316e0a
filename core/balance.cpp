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
//
// With several threads (BalanceOptions::n_threads) each level's candidates are generated and
// sorted in parallel, in pieces cut at sibling groups, and merged; the final walk is cut into
// subtrees whose place in the output is known beforehand from counts of internal cells, so the
// threads write their parts of the result directly. The result is the same for any thread count.

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <sstream>

#include "core/error.hpp"
#include "core/orthtree.hpp"
#include "core/worker_pool.hpp"

namespace febemesh {
namespace {

/// A mask of axis d's bits in a Morton key (levels 1..max_level).
template <int Dim> constexpr std::uint64_t axis_mask(int d) {
  std::uint64_t m = 0;
  for (int b = 0; b < max_level<Dim>; ++b) m |= std::uint64_t(1) << (Dim * b + d);
  return m;
}
/// All axes' masks, computed at compile time: axis_mask(d) with d known only at run time was a
/// loop per call (balance, flange level 9: 48 M of its 105 M instructions).
template <int Dim> constexpr std::array<std::uint64_t, Dim> axis_masks() {
  std::array<std::uint64_t, Dim> m{};
  for (int d = 0; d < Dim; ++d) m[d] = axis_mask<Dim>(d);
  return m;
}

/// Same-level neighbour of the cell with Morton key `key` at `level`, moved by `dir` (entries in
/// {-1, 0, 1}), computed on the dilated key directly; false when it leaves the root.
template <int Dim>
inline bool neighbour_key(std::uint64_t key, int level, const int* dir, std::uint64_t& out) {
  static constexpr std::array<std::uint64_t, Dim> masks = axis_masks<Dim>();
  const int shift = Dim * (max_level<Dim> - level);
  std::uint64_t result = 0;
  for (int d = 0; d < Dim; ++d) {
    const std::uint64_t mask = masks[d];
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

/// For each set of internal children of a parent (bit k = child k), the directions in which the
/// parent's same-size neighbours are required. A direction is a subset of axes plus a side on
/// each; it leaves the parent only from a child lying on that side along every axis of the
/// subset. Tabulated once per balance, so that the per-group work is a short list.
template <int Dim> struct DirectionTable {
  static constexpr int nc = Cube<Dim>::n_children;
  std::vector<std::array<int, Dim>> dirs;
  std::array<std::uint32_t, (1u << nc) + 1> first{};  // dirs[first[m] .. first[m+1]) for mask m

  explicit DirectionTable(BalanceKind kind) {
    for (unsigned present = 0; present < (1u << nc); ++present) {
      first[present] = std::uint32_t(dirs.size());
      for (int axes = 1; axes < nc; ++axes) {
        if (!Directions<Dim>::wanted(axes, kind)) continue;
        for (int signs = 0; signs < nc; ++signs) {
          if ((signs & ~axes) != 0) continue;
          bool reachable = false;
          for (int k = 0; k < nc; ++k) {
            if (((present >> k) & 1u) && (k & axes) == signs) reachable = true;
          }
          if (!reachable) continue;
          std::array<int, Dim> dir;
          for (int d = 0; d < Dim; ++d) dir[d] = ((axes >> d) & 1) ? (((signs >> d) & 1) ? 1 : -1) : 0;
          dirs.push_back(dir);
        }
      }
    }
    first[1u << nc] = std::uint32_t(dirs.size());
  }
};

/// Appends to `out` the parents of the sibling groups in here[begin, end) (internal cells at
/// `level`) and the same-size neighbours of those parents that the rule requires.
template <int Dim>
void append_candidates(const std::vector<std::uint64_t>& here, std::size_t begin, std::size_t end, int level,
                       const DirectionTable<Dim>& table, std::vector<std::uint64_t>& out) {
  constexpr std::size_t nc = Cube<Dim>::n_children;
  const int pl = level - 1;
  const std::uint64_t parent_mask = ~((std::uint64_t(1) << (Dim * (max_level<Dim> - pl))) - 1);
  const int child_shift = Dim * (max_level<Dim> - level);
  // One sibling group at a time: the union of outward sides of its internal children says
  // which neighbours of the parent are required.
  for (std::size_t i = begin; i < end;) {
    const std::uint64_t pk = here[i] & parent_mask;
    unsigned present = 0;  // bit k: child k of the parent is internal
    for (; i < end && (here[i] & parent_mask) == pk; ++i) {
      present |= 1u << ((here[i] >> child_shift) & (nc - 1));
    }
    out.push_back(pk);
    for (std::uint32_t j = table.first[present]; j < table.first[present + 1]; ++j) {
      std::uint64_t nk;
      if (neighbour_key<Dim>(pk, pl, table.dirs[j].data(), nk)) out.push_back(nk);
    }
  }
}

/// Writes the leaves of the subtree below internal cell `p` (index `index` at its level) in
/// Morton order: children of internal cells that are not internal. A depth-first walk meets each
/// level's internal cells in increasing key order, so one cursor per level suffices.
template <int Dim> struct Walker {
  const std::vector<std::vector<std::uint8_t>>& masks;
  std::vector<std::size_t> cursor;  // per level: index of the next internal cell
  Cell<Dim>* out;

  void walk(const Cell<Dim>& p, std::size_t index) {
    constexpr int nc = Cube<Dim>::n_children;
    const int level = p.level + 1;
    const std::uint32_t half = std::uint32_t(1) << (max_level<Dim> - level);
    const unsigned mask = masks[p.level][index];
    for (int i = 0; i < nc; ++i) {
      Cell<Dim> ch;
      ch.level = std::uint8_t(level);
      for (int d = 0; d < Dim; ++d) ch.anchor[d] = p.anchor[d] + (((i >> d) & 1) ? half : 0);
      if ((mask >> i) & 1u) {
        walk(ch, cursor[std::size_t(level)]++);
      } else {
        ::new (static_cast<void*>(out++)) Cell<Dim>(ch);
      }
    }
  }
};

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
  // sorted from the Morton-ordered leaves (masking low bits is monotone). On several threads
  // each takes a contiguous part of the leaves; the parts' lists are concatenated in order,
  // where only a parent straddling two parts can repeat.
  const int n_threads = std::max(1, opt.n_threads);
  const int n_parts = leaves.size() < 65536 ? 1 : n_threads;
  std::vector<std::vector<std::vector<std::uint64_t>>> parts(
      static_cast<std::size_t>(n_parts), std::vector<std::vector<std::uint64_t>>(static_cast<std::size_t>(deepest)));
  run_on_threads(n_parts, [&](int t) {
    auto& mine = parts[std::size_t(t)];
    const std::size_t begin = leaves.size() * std::size_t(t) / std::size_t(n_parts);
    const std::size_t end = leaves.size() * std::size_t(t + 1) / std::size_t(n_parts);
    for (std::size_t i = begin; i < end; ++i) {
      const Cell<Dim>& c = leaves[i];
      if (c.level == 0) continue;
      const int pl = c.level - 1;
      const std::uint64_t pk =
          detail::interleave<Dim>(c.anchor) & ~((std::uint64_t(1) << (Dim * (max_level<Dim> - pl))) - 1);
      auto& v = mine[std::size_t(pl)];
      if (v.empty() || v.back() != pk) v.push_back(pk);
    }
  });
  std::vector<std::vector<std::uint64_t>> internal = std::move(parts[0]);
  for (std::size_t t = 1; t < parts.size(); ++t) {
    for (int level = 0; level < deepest; ++level) {
      auto& v = internal[std::size_t(level)];
      auto& more = parts[t][std::size_t(level)];
      const std::size_t skip = !v.empty() && !more.empty() && more.front() == v.back() ? 1 : 0;
      v.insert(v.end(), more.begin() + std::ptrdiff_t(skip), more.end());
      std::vector<std::uint64_t>().swap(more);
    }
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
    const DirectionTable<Dim> table(kind);
    // One cache line per thread's vector: push_back updates its end pointer on every key.
    struct alignas(64) Keys {
      std::vector<std::uint64_t> v;
    };
    std::vector<Keys> candidates(static_cast<std::size_t>(n_threads));
    std::vector<std::uint64_t> merged;
    for (int level = deepest - 1; level >= 1; --level) {
      const auto& here = internal[level];
      const std::uint64_t parent_mask = ~(volume_units(Cell<Dim>{{}, std::uint8_t(level - 1)}) - 1);
      // Pieces of `here` cut at sibling groups (a group must not be split: its children
      // together decide the parent's neighbours); small levels stay on one thread.
      const int n_pieces = here.size() < 4096 ? 1 : n_threads;
      std::vector<std::size_t> cut(static_cast<std::size_t>(n_pieces) + 1, here.size());
      cut[0] = 0;
      for (int t = 1; t < n_pieces; ++t) {
        std::size_t c = std::max(cut[std::size_t(t) - 1], here.size() * std::size_t(t) / std::size_t(n_pieces));
        while (c > 0 && c < here.size() && (here[c] & parent_mask) == (here[c - 1] & parent_mask)) ++c;
        cut[std::size_t(t)] = c;
      }
      run_on_threads(n_pieces, [&](int t) {
        auto& mine = candidates[std::size_t(t)].v;
        mine.clear();
        append_candidates<Dim>(here, cut[std::size_t(t)], cut[std::size_t(t) + 1], level, table, mine);
        std::sort(mine.begin(), mine.end());
        mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
      });
      // Merge the sorted pieces into the level above (a union: keys may repeat across pieces).
      auto& below = internal[level - 1];
      for (int t = 0; t < n_pieces; ++t) {
        const auto& mine = candidates[std::size_t(t)].v;
        merged.clear();
        merged.reserve(mine.size() + below.size());
        std::set_union(mine.begin(), mine.end(), below.begin(), below.end(), std::back_inserter(merged));
        n_internal += merged.size() - below.size();
        below.swap(merged);
      }
      check_limit(false);
    }
  }  // the work arrays are freed before the output is allocated
  check_limit(true);

  // The walk below needs, per internal cell, only which of its children are internal: one byte
  // instead of an 8-byte key. Built top-down so that each level's keys are freed once used.
  std::vector<std::vector<std::uint8_t>> masks(static_cast<std::size_t>(deepest));
  for (int level = 0; level < deepest; ++level) {
    const auto& here = internal[level];
    auto& m = masks[level];
    m.assign(here.size(), 0);
    if (level + 1 < deepest) {
      const auto& next = internal[level + 1];
      const std::uint64_t parent_mask = ~(volume_units(Cell<Dim>{{}, std::uint8_t(level)}) - 1);
      const int child_shift = Dim * (max_level<Dim> - level - 1);
      // Pieces of `next` cut at sibling groups, so that no two threads write the same byte.
      const int n_pieces = next.size() < 4096 ? 1 : n_threads;
      run_on_threads(n_pieces, [&](int t) {
        std::size_t i = next.size() * std::size_t(t) / std::size_t(n_pieces);
        std::size_t end = next.size() * std::size_t(t + 1) / std::size_t(n_pieces);
        const auto group_start = [&](std::size_t c) {
          while (c > 0 && c < next.size() && (next[c] & parent_mask) == (next[c - 1] & parent_mask)) ++c;
          return c;
        };
        i = group_start(i);
        end = group_start(end);
        if (i >= end) return;
        std::size_t j = std::size_t(std::lower_bound(here.begin(), here.end(), next[i] & parent_mask) - here.begin());
        for (; i < end; ++i) {
          const std::uint64_t key = next[i];
          const std::uint64_t pk = key & parent_mask;
          while (here[j] != pk) ++j;  // every internal cell's parent is internal
          m[j] = std::uint8_t(m[j] | (1u << ((key >> child_shift) & (nc - 1))));
        }
      });
    }
    std::vector<std::uint64_t>().swap(internal[level]);
  }

  // The output, cut into tasks: the internal cells of one split level s, whose subtrees hold
  // every deeper internal cell, and the leaves above s between them. A task's leaves number
  // 1 + (nc - 1) x (its internal cells), and its first internal cell at each level L >= s is
  // the running count of internal children (popcounts of the masks) of the cells before it, so
  // every task knows where its leaves go and where its cursors start before any is walked.
  const std::size_t n_out = 1 + n_internal * (nc - 1);
  int split = 0;
  if (n_threads > 1) {
    while (split + 1 < deepest && masks[std::size_t(split)].size() < std::size_t(n_threads) * 64) ++split;
  }
  const std::size_t n_levels = std::size_t(deepest - split);
  const std::size_t n_tasks = masks[std::size_t(split)].size();
  // first[k * n_levels + (L - split)]: index of task k's first internal cell at level L; row
  // n_tasks holds the level sizes.
  std::vector<std::size_t> first((n_tasks + 1) * n_levels);
  for (std::size_t k = 0; k <= n_tasks; ++k) first[k * n_levels] = k;
  for (std::size_t l = 0; l + 1 < n_levels; ++l) {
    const auto& m = masks[std::size_t(split) + l];
    std::size_t pos = 0, count = 0;
    for (std::size_t k = 0; k <= n_tasks; ++k) {
      const std::size_t upto = first[k * n_levels + l];
      for (; pos < upto; ++pos) count += std::size_t(std::popcount(unsigned(m[pos])));
      first[k * n_levels + l + 1] = count;
    }
  }
  // The walk above the split level, in Morton order: leaves, and tasks (marked by level).
  struct Item {
    Cell<Dim> cell;
    std::size_t task = no_leaf;  // or the index of the internal cell at the split level
  };
  std::vector<Item> items;
  {
    std::vector<std::size_t> cursor(static_cast<std::size_t>(split) + 1, 0);
    const auto top = [&](const auto& self, const Cell<Dim>& p, std::size_t index) -> void {
      if (p.level == split) {
        items.push_back({p, index});
        return;
      }
      const int level = p.level + 1;
      const std::uint32_t half = std::uint32_t(1) << (max_level<Dim> - level);
      const unsigned mask = masks[p.level][index];
      for (int i = 0; i < int(nc); ++i) {
        Cell<Dim> ch;
        ch.level = std::uint8_t(level);
        for (int d = 0; d < Dim; ++d) ch.anchor[d] = p.anchor[d] + (((i >> d) & 1) ? half : 0);
        if ((mask >> i) & 1u) {
          self(self, ch, cursor[std::size_t(level)]++);
        } else {
          items.push_back({ch, no_leaf});
        }
      }
    };
    top(top, Cell<Dim>{}, 0);
  }
  std::vector<std::size_t> offset(items.size() + 1, 0);
  for (std::size_t i = 0; i < items.size(); ++i) {
    std::size_t n = 1;
    if (items[i].task != no_leaf) {
      const std::size_t k = items[i].task;
      std::size_t n_int = 0;
      for (std::size_t l = 0; l < n_levels; ++l) n_int += first[(k + 1) * n_levels + l] - first[k * n_levels + l];
      n = 1 + n_int * (nc - 1);
    }
    offset[i + 1] = offset[i] + n;
  }
  MESH_ASSERT(offset.back() == n_out, "balanced tree has " << offset.back() << " leaves for " << n_internal
                                                           << " internal cells");
  LeafVector<Dim> out;
  out.resize(n_out);  // sized, not written (LeafAllocator): each cell is written once below
  Cell<Dim>* const cells = out.data();
  const std::size_t n_chunks = n_threads == 1 ? 1 : std::min(items.size(), std::size_t(n_threads) * 16);
  std::atomic<std::size_t> next{0};
  run_on_threads(n_threads, [&](int) {
    Walker<Dim> w{masks, std::vector<std::size_t>(static_cast<std::size_t>(deepest) + 1, 0), nullptr};
    for (std::size_t c; (c = next.fetch_add(1)) < n_chunks;) {
      for (std::size_t i = items.size() * c / n_chunks, e = items.size() * (c + 1) / n_chunks; i < e; ++i) {
        w.out = cells + offset[i];
        if (items[i].task == no_leaf) {
          ::new (static_cast<void*>(w.out)) Cell<Dim>(items[i].cell);
          continue;
        }
        const std::size_t k = items[i].task;
        for (std::size_t l = 0; l < n_levels; ++l) w.cursor[std::size_t(split) + l] = first[k * n_levels + l];
        w.walk(items[i].cell, k);
        MESH_ASSERT(w.out == cells + offset[i + 1], "task " << k << " wrote " << (w.out - cells - offset[i])
                                                            << " leaves, expected " << (offset[i + 1] - offset[i]));
      }
    }
  });
  return Orthtree<Dim>(t.root_box(), std::move(out));
}

template Orthtree<2> balance_2to1<2>(const Orthtree<2>&, BalanceKind, const BalanceOptions&);
template Orthtree<3> balance_2to1<3>(const Orthtree<3>&, BalanceKind, const BalanceOptions&);

}  // namespace febemesh
