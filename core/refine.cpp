// Refinement: the paper's check_and_subdivide_quadrant, refinement by flags and by predicate.
// Leaves are emitted by depth-first recursion, which visits children in Morton order, so the
// output is sorted without a sort. Parallel runs split the work into an ordered list of subtrees
// (the paper: "one processor can subdivide a quadrant and send them to four processors"), expand
// them independently and concatenate in order, so any thread count gives the serial result.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <new>
#include <sstream>
#include <thread>

#include <sys/mman.h>

#include "core/error.hpp"
#include "core/huge_pages.hpp"
#include "core/orthtree.hpp"

namespace febemesh {
namespace {

/// Shared leaf budget: counts leaves and the lattice volume they cover, so that a refusal can
/// estimate the final size from the fraction of the root already covered.
struct Budget {
  std::size_t max_leaves = 0;
  std::uint64_t root_volume = 0;
  std::size_t cell_bytes = 0;
  std::atomic<std::size_t> leaves{0};
  std::atomic<std::uint64_t> volume{0};
  std::atomic<bool> stop{false};

  [[noreturn]] void refuse() const {
    const double done = double(leaves.load());
    const double fraction = std::max(double(volume.load()) / double(root_volume), 1e-300);
    const double estimate = std::max(done, done / fraction);
    std::ostringstream os;
    os << "refinement would create about " << std::llround(std::min(estimate, 1e18))
       << " leaves (about " << std::llround(std::min(estimate * double(cell_bytes) / 1048576.0, 1e18))
       << " MiB at " << cell_bytes << " bytes per leaf), more than max_leaves = " << max_leaves
       << "; raise the limit or coarsen the control parameter";
    throw LimitError(os.str());
  }
};

/// Append-only storage of emitted leaves in blocks mapped straight from the kernel. A growing
/// std::vector would hold its old and new buffers at once (up to 2x the leaves at the last
/// doubling), and blocks from malloc may stay resident after free (glibc raises its mmap
/// threshold once a large block is freed, and the next blocks then come from an arena that is
/// not trimmed). Own mappings are released the moment they are unmapped, so draining the spool
/// front to back into an exactly reserved vector keeps the peak at the leaves plus one block.
template <int Dim> class LeafSpool {
 public:
  LeafSpool() = default;
  LeafSpool(const LeafSpool&) = delete;
  LeafSpool& operator=(const LeafSpool&) = delete;
  ~LeafSpool() {
    for (Cell<Dim>* b : blocks_) {
      if (b) munmap(b, block_bytes);
    }
  }

  void push(const Cell<Dim>& c) {
    if (fill_ == per_block) grow();
    new (blocks_.back() + fill_) Cell<Dim>(c);
    ++fill_;
    ++size_;
  }
  std::size_t size() const { return size_; }
  /// Appends leaves [begin, end) to `out`. Ranges must be drained in increasing order: blocks
  /// wholly before `end` are unmapped.
  void drain(std::size_t begin, std::size_t end, std::vector<Cell<Dim>>& out) {
    while (begin < end) {
      const std::size_t b = begin / per_block, stop = std::min(end, (b + 1) * per_block);
      out.insert(out.end(), blocks_[b] + (begin - b * per_block), blocks_[b] + (stop - b * per_block));
      if (stop == (b + 1) * per_block) {
        munmap(blocks_[b], block_bytes);
        blocks_[b] = nullptr;
      }
      begin = stop;
    }
  }

 private:
  static constexpr std::size_t block_bytes = std::size_t(1) << 21;  // one huge page
  static constexpr std::size_t per_block = block_bytes / sizeof(Cell<Dim>);

  void grow() {
    // Map twice the size and trim to a 2 MiB-aligned block, so that it can be one huge page.
    constexpr int prot = PROT_READ | PROT_WRITE, flags = MAP_PRIVATE | MAP_ANONYMOUS;
    void* raw = mmap(nullptr, 2 * block_bytes, prot, flags, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const std::uintptr_t r = reinterpret_cast<std::uintptr_t>(raw);
    const std::uintptr_t a = (r + block_bytes - 1) & ~std::uintptr_t(block_bytes - 1);
    if (a > r) munmap(raw, a - r);
    if (a + block_bytes < r + 2 * block_bytes) munmap(reinterpret_cast<void*>(a + block_bytes), r + block_bytes - a);
    auto* block = reinterpret_cast<Cell<Dim>*>(a);
    advise_huge_pages(block, block_bytes);
    blocks_.push_back(block);
    fill_ = 0;
  }

  std::vector<Cell<Dim>*> blocks_;
  std::size_t fill_ = per_block;  // leaves in the last block
  std::size_t size_ = 0;
};

/// Appends leaves to one spool and reports to the budget every few thousand leaves, so that
/// memory stays bounded by max_leaves plus one batch per thread.
template <int Dim> class Emitter {
 public:
  Emitter(LeafSpool<Dim>& out, Budget& budget) : out_(out), budget_(budget) {}

  void emit(const Cell<Dim>& c) {
    out_.push(c);
    volume_ += volume_units(c);
    if (++pending_ == batch) flush();
  }
  void flush() {
    const std::size_t total = budget_.leaves.fetch_add(pending_) + pending_;
    budget_.volume.fetch_add(volume_);
    pending_ = 0;
    volume_ = 0;
    if (total > budget_.max_leaves) {
      budget_.stop = true;
      budget_.refuse();
    }
    if (budget_.stop) throw LimitError("refinement stopped: another thread exceeded max_leaves");
  }

 private:
  static constexpr std::size_t batch = 4096;
  LeafSpool<Dim>& out_;
  Budget& budget_;
  std::size_t pending_ = 0;
  std::uint64_t volume_ = 0;
};

/// A unit of work in Morton order: a leaf to emit as is, or a subtree root to expand.
template <int Dim> struct Item {
  Cell<Dim> cell;
  bool expand = false;
};

template <int Dim> inline Cell<Dim> make_child(const Cell<Dim>& c, int i) {
  Cell<Dim> ch;
  ch.level = std::uint8_t(c.level + 1);
  const std::uint32_t half = std::uint32_t(1) << (max_level<Dim> - ch.level);
  for (int d = 0; d < Dim; ++d) ch.anchor[d] = c.anchor[d] + (((i >> d) & 1) ? half : 0);
  return ch;
}

/// The paper's rule with a level cap.
template <int Dim> struct ControlRule {
  const Orthtree<Dim>& frame;  // root cube only, for the real boxes
  const ControlFn<Dim>& control;
  int cap;

  /// Split and check the children again (true), or split once and stop (false).
  bool split_again(const Cell<Dim>& c) const {
    return c.level + 1 < cap && control(geometry(frame, c)) > double(c.level + 1);
  }
  /// One step of the rule: append what `c` becomes, as leaves or subtrees still to expand.
  void step(const Cell<Dim>& c, std::vector<Item<Dim>>& out) const {
    if (c.level >= cap) {
      out.push_back({c, false});
      return;
    }
    const bool again = split_again(c);
    for (int i = 0; i < Cube<Dim>::n_children; ++i) out.push_back({make_child(c, i), again});
  }
  void run(const Cell<Dim>& c, Emitter<Dim>& e) const {
    if (c.level >= cap) {
      e.emit(c);
    } else if (split_again(c)) {
      for (int i = 0; i < Cube<Dim>::n_children; ++i) run(make_child(c, i), e);
    } else {
      for (int i = 0; i < Cube<Dim>::n_children; ++i) e.emit(make_child(c, i));
    }
  }
};

template <int Dim> struct PredicateRule {
  const std::function<bool(const Cell<Dim>&)>& pred;
  int cap;

  void run(const Cell<Dim>& c, Emitter<Dim>& e) const {
    if (c.level < cap && pred(c)) {
      for (int i = 0; i < Cube<Dim>::n_children; ++i) run(make_child(c, i), e);
    } else {
      e.emit(c);
    }
  }
};

/// Touches every page of freshly reserved storage on n_threads threads. The kernel zeroes a
/// page on its first touch, which otherwise happens in the serial copy into the result and was
/// a tenth of a refinement's time (measured), the part that two threads could not share. The
/// bytes are storage, not yet elements: the copy overwrites them.
inline void prefault(void* storage, std::size_t bytes, int n_threads) {
  constexpr std::size_t page = 4096;
  auto* base = static_cast<unsigned char*>(storage);
  const auto touch = [base, bytes](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end && i < bytes; i += page) {
      *reinterpret_cast<volatile unsigned char*>(base + i) = 0;
    }
  };
  const std::size_t pages = (bytes + page - 1) / page;
  std::vector<std::thread> threads;
  for (int t = 1; t < n_threads; ++t) {
    threads.emplace_back(touch, pages * std::size_t(t) / std::size_t(n_threads) * page,
                         pages * std::size_t(t + 1) / std::size_t(n_threads) * page);
  }
  touch(0, pages / std::size_t(n_threads) * page);
  for (auto& th : threads) th.join();
}

/// Runs work(k, emitter) for k = 0..n_work-1 in order on n_threads threads and returns the
/// leaves in that order. The result does not depend on the thread count: the work is cut into
/// contiguous chunks, each chunk's leaves form one range of its thread's spool, and the ranges
/// are concatenated in chunk order. Threads take chunks in increasing order, so each spool is
/// drained front to back and frees its blocks as it goes.
template <int Dim, class Work>
std::vector<Cell<Dim>> expand_in_order(std::size_t n_work, const Work& work, Budget& budget, int n_threads) {
  const int n_spools = std::max(1, n_threads);
  std::vector<LeafSpool<Dim>> spools(static_cast<std::size_t>(n_spools));
  struct Range {
    int spool = 0;
    std::size_t begin = 0, end = 0;
  };
  const auto process = [&](std::size_t begin, std::size_t end, int spool, Range& range) {
    LeafSpool<Dim>& out = spools[std::size_t(spool)];
    range = {spool, out.size(), 0};
    Emitter<Dim> e(out, budget);
    for (std::size_t k = begin; k < end; ++k) work(k, e);
    e.flush();
    range.end = out.size();
  };
  // Many more chunks than threads, taken dynamically: refinement is concentrated near the
  // boundary, so equal item counts are far from equal work.
  const std::size_t n_chunks = n_threads <= 1 ? std::min<std::size_t>(n_work, 1)
                                              : std::min(n_work, std::size_t(n_threads) * 16);
  std::vector<Range> ranges(n_chunks);
  if (n_chunks == 1) {
    process(0, n_work, 0, ranges[0]);
  } else if (n_chunks > 1) {
    std::vector<std::exception_ptr> errors(n_chunks);
    std::atomic<std::size_t> next{0};
    const auto worker = [&](int spool) {
      for (;;) {
        const std::size_t k = next.fetch_add(1);
        if (k >= n_chunks || budget.stop) return;
        try {
          process(n_work * k / n_chunks, n_work * (k + 1) / n_chunks, spool, ranges[k]);
        } catch (...) {
          errors[k] = std::current_exception();
          budget.stop = true;
        }
      }
    };
    std::vector<std::thread> threads;
    for (int t = 1; t < n_threads; ++t) threads.emplace_back(worker, t);
    worker(0);
    for (auto& th : threads) th.join();
    // The first refusal that exceeded the budget carries the estimate; prefer it over the
    // "stopped" notes of the other chunks.
    std::exception_ptr first;
    for (const auto& err : errors) {
      if (!err) continue;
      try {
        std::rethrow_exception(err);
      } catch (const LimitError& le) {
        if (std::string(le.what()).rfind("refinement would", 0) == 0) throw;
        if (!first) first = err;
      } catch (...) {
        throw;
      }
    }
    if (first) std::rethrow_exception(first);
  }
  std::size_t total = 0;
  for (const auto& s : spools) total += s.size();
  std::vector<Cell<Dim>> out;
  out.reserve(total);  // exact: pages are touched only as the spools drain into it
  advise_huge_pages(out.data(), total * sizeof(Cell<Dim>));
  if (n_threads > 1) prefault(out.data(), total * sizeof(Cell<Dim>), n_threads);
  for (const Range& r : ranges) spools[std::size_t(r.spool)].drain(r.begin, r.end, out);
  return out;
}

/// Expands `items` in order with `rule`.
template <int Dim, class Rule>
std::vector<Cell<Dim>> expand_items(const std::vector<Item<Dim>>& items, const Rule& rule,
                                    Budget& budget, int n_threads) {
  return expand_in_order<Dim>(
      items.size(),
      [&](std::size_t k, Emitter<Dim>& e) {
        if (items[k].expand) {
          rule.run(items[k].cell, e);
        } else {
          e.emit(items[k].cell);
        }
      },
      budget, n_threads);
}

template <int Dim> int level_cap(const RefineOptions& opt) {
  const int cap = opt.max_level < 0 ? max_level<Dim> : opt.max_level;
  if (cap > max_level<Dim>) {
    throw LimitError("max_level " + std::to_string(cap) + " exceeds the lattice depth " +
                     std::to_string(max_level<Dim>));
  }
  return cap;
}

template <int Dim> void init_budget(Budget& b, const RefineOptions& opt) {
  b.max_leaves = opt.max_leaves;
  b.root_volume = volume_units(Cell<Dim>{});
  b.cell_bytes = sizeof(Cell<Dim>);
}

}  // namespace

template <int Dim>
Orthtree<Dim> subdivide_by_control(const Box<Dim>& domain, const ControlFn<Dim>& control,
                                   const RefineOptions& opt) {
  const Orthtree<Dim> frame(domain);
  const ControlRule<Dim> rule{frame, control, level_cap<Dim>(opt)};
  Budget budget;
  init_budget<Dim>(budget, opt);
  std::vector<Item<Dim>> items{{Cell<Dim>{}, true}};
  if (opt.n_threads > 1) {
    // Apply the rule breadth-first at shallow levels until there are enough subtrees to share.
    const std::size_t wanted = std::size_t(opt.n_threads) * 64;
    for (;;) {
      const auto n_expand = std::count_if(items.begin(), items.end(), [](const Item<Dim>& it) { return it.expand; });
      if (n_expand == 0 || std::size_t(n_expand) >= wanted || items.size() > opt.max_leaves) break;
      std::vector<Item<Dim>> next;
      next.reserve(items.size() * Cube<Dim>::n_children);
      for (const auto& it : items) {
        if (it.expand) {
          rule.step(it.cell, next);
        } else {
          next.push_back(it);
        }
      }
      items.swap(next);
    }
  }
  return Orthtree<Dim>(frame.root_box(), expand_items(items, rule, budget, opt.n_threads));
}

template <int Dim>
Flags mark(const Orthtree<Dim>& t, const std::function<bool(const Cell<Dim>&)>& pred) {
  Flags flags(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i) flags[i] = pred(t.leaf(i)) ? 1 : 0;
  return flags;
}

template <int Dim> Orthtree<Dim> refine(const Orthtree<Dim>& t, const Flags& flags) {
  if (flags.size() != t.n_leaves()) {
    throw InputError("refine: " + std::to_string(flags.size()) + " flags for " +
                     std::to_string(t.n_leaves()) + " leaves");
  }
  std::size_t n_flagged = 0;
  for (std::size_t i = 0; i < flags.size(); ++i) {
    if (!flags[i]) continue;
    ++n_flagged;
    if (t.leaf(i).level >= max_level<Dim>) {
      throw LimitError("refine: leaf " + std::to_string(i) + " is already at the deepest level " +
                       std::to_string(max_level<Dim>));
    }
  }
  std::vector<Cell<Dim>> out;
  out.reserve(t.n_leaves() + n_flagged * (Cube<Dim>::n_children - 1));
  advise_huge_pages(out.data(), out.capacity() * sizeof(Cell<Dim>));
  for (std::size_t i = 0; i < flags.size(); ++i) {
    if (flags[i]) {
      for (int k = 0; k < Cube<Dim>::n_children; ++k) out.push_back(make_child(t.leaf(i), k));
    } else {
      out.push_back(t.leaf(i));
    }
  }
  return Orthtree<Dim>(t.root_box(), std::move(out));
}

template <int Dim>
Orthtree<Dim> refine_while(const Orthtree<Dim>& t, const std::function<bool(const Cell<Dim>&)>& pred,
                           const RefineOptions& opt) {
  const PredicateRule<Dim> rule{pred, level_cap<Dim>(opt)};
  Budget budget;
  init_budget<Dim>(budget, opt);
  // Every input leaf is a subtree root to expand: index the leaves directly (no item copies).
  const auto& leaves = t.leaves();
  return Orthtree<Dim>(t.root_box(),
                       expand_in_order<Dim>(
                           leaves.size(), [&](std::size_t k, Emitter<Dim>& e) { rule.run(leaves[k], e); },
                           budget, opt.n_threads));
}

#define FEBEMESH_INSTANTIATE_REFINE(D)                                                              \
  template Orthtree<D> subdivide_by_control<D>(const Box<D>&, const ControlFn<D>&, const RefineOptions&); \
  template Flags mark<D>(const Orthtree<D>&, const std::function<bool(const Cell<D>&)>&);          \
  template Orthtree<D> refine<D>(const Orthtree<D>&, const Flags&);                                \
  template Orthtree<D> refine_while<D>(const Orthtree<D>&, const std::function<bool(const Cell<D>&)>&, \
                                       const RefineOptions&);

FEBEMESH_INSTANTIATE_REFINE(2)
FEBEMESH_INSTANTIATE_REFINE(3)

}  // namespace febemesh
