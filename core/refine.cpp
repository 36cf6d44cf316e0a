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
#include <memory>
#include <new>
#include <sstream>

#include <sys/mman.h>

#include "core/error.hpp"
#include "core/orthtree.hpp"
#include "core/worker_pool.hpp"

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

/// Append-only storage of emitted leaves, one byte each: the level. The leaves of one work range
/// tile a cube in Morton order, so each leaf's key is the previous key plus the previous leaf's
/// volume, starting from the range's first key; the cells are rebuilt (a branch-free
/// de-interleave, measured faster in 2D than a bit-by-bit carry, whose branches mispredict) only
/// when they are written into the result. Writing 12-16 bytes per leaf twice (a cell spool, then the result) made refinement
/// bound by memory bandwidth, which two threads of this machine do not double (measured: page
/// zeroing was about half of a two-thread run). Blocks are mapped straight from the kernel and
/// unmapped as they drain, so the spool adds at most one small block per thread to the peak.
// Aligned to a cache line: the threads' spools sit side by side in one vector, and push()
// updates the counters on every leaf (measured: sharing a line made each of two threads spend
// the serial run's whole CPU time on the expansion).
class alignas(64) LevelSpool {
 public:
  LevelSpool() = default;
  LevelSpool(const LevelSpool&) = delete;
  LevelSpool& operator=(const LevelSpool&) = delete;
  ~LevelSpool() {
    for (std::uint8_t* b : blocks_) {
      if (b) munmap(b, block_bytes);
    }
  }

  void push(std::uint8_t level) {
    if (fill_ == block_bytes) grow();
    blocks_.back()[fill_++] = level;
    ++size_;
  }
  std::size_t size() const { return size_; }
  /// Ends appending: from here on the leaves may be read by several threads, each block being
  /// unmapped by the reader that consumes its last leaf.
  void seal() {
    remaining_ = std::make_unique<std::atomic<std::size_t>[]>(blocks_.size());
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      remaining_[b].store(b + 1 < blocks_.size() ? block_bytes : fill_, std::memory_order_relaxed);
    }
  }
  /// Calls f(level) for the leaves [begin, end) and releases them (after seal(); every leaf is
  /// read so exactly once).
  template <class F> void consume(std::size_t begin, std::size_t end, F&& f) {
    while (begin < end) {
      const std::size_t b = begin / block_bytes, stop = std::min(end, (b + 1) * block_bytes);
      const std::uint8_t* block = blocks_[b];
      for (std::size_t i = begin - b * block_bytes, n = stop - b * block_bytes; i < n; ++i) f(block[i]);
      if (remaining_[b].fetch_sub(stop - begin, std::memory_order_acq_rel) == stop - begin) {
        munmap(blocks_[b], block_bytes);
        blocks_[b] = nullptr;
      }
      begin = stop;
    }
  }
 private:
  // Small pages: a block holds 256 Ki leaves and costs one fault per 4096 of them; a huge page
  // would keep 2 MiB resident per thread for trees of any size.
  static constexpr std::size_t block_bytes = std::size_t(1) << 18;

  void grow() {
    void* raw = mmap(nullptr, block_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    blocks_.push_back(static_cast<std::uint8_t*>(raw));
    fill_ = 0;
  }

  std::vector<std::uint8_t*> blocks_;
  std::size_t fill_ = block_bytes;  // bytes used in the last block
  std::size_t size_ = 0;
  std::unique_ptr<std::atomic<std::size_t>[]> remaining_;  // per block, leaves not yet consumed
};

template <int Dim> inline std::uint64_t volume_of_level(int level) {
  return std::uint64_t(1) << (Dim * (max_level<Dim> - level));
}

/// Records leaves in one spool and reports to the budget every few thousand leaves, so that
/// memory stays bounded by max_leaves plus one batch per thread.
template <int Dim> class Emitter {
 public:
  Emitter(LevelSpool& out, Budget& budget) : out_(out), budget_(budget) {}

  void emit(const Cell<Dim>& c) {
    if (!started_) {
      first_ = c.anchor;
      started_ = true;
    }
    out_.push(c.level);
    volume_ += volume_of_level<Dim>(c.level);
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
  /// Anchor of the first leaf emitted (meaningful once one was).
  const std::array<std::uint32_t, Dim>& first() const { return first_; }

 private:
  static constexpr std::size_t batch = 4096;
  LevelSpool& out_;
  Budget& budget_;
  std::size_t pending_ = 0;
  std::uint64_t volume_ = 0;
  std::array<std::uint32_t, Dim> first_{};
  bool started_ = false;
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
    return c.level + 1 < cap && control(box(c)) > double(c.level + 1);
  }
  /// geometry(frame, c), inline (the same arithmetic, so the same doubles): it is evaluated
  /// once per split cell, and the out-of-line call was a twentieth of a refinement (measured).
  Box<Dim> box(const Cell<Dim>& c) const {
    Box<Dim> b;
    const double len = double(std::uint32_t(1) << (max_level<Dim> - c.level));
    const double unit = frame.unit();
    for (int d = 0; d < Dim; ++d) {
      b.lo[d] = frame.root_box().lo[d] + unit * double(c.anchor[d]);
      b.hi[d] = frame.root_box().lo[d] + unit * (double(c.anchor[d]) + len);
    }
    return b;
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

/// Runs work(k, emitter) for k = 0..n_work-1 in order on n_threads threads and returns the
/// leaves in that order. The result does not depend on the thread count: the work is cut into
/// contiguous chunks, each chunk's leaves form one range of its thread's spool, and the ranges
/// are placed in chunk order. Two phases: the threads expand chunks (taken dynamically, in
/// increasing order), then, with every chunk's size and so its place in the result known, they
/// write the chunks' cells there (again taken dynamically), reading whichever spools hold them;
/// a spool block is unmapped as soon as its last leaf is read. Both phases run in parallel: a serial copy into
/// the result was a third of a refinement (measured) and kept two threads near 1x.
template <int Dim, class Work>
LeafVector<Dim> expand_in_order(std::size_t n_work, const Work& work, Budget& budget, int n_threads) {
  n_threads = std::max(1, n_threads);
  std::vector<LevelSpool> spools(static_cast<std::size_t>(n_threads));
  struct Range {
    int spool = 0;
    std::size_t begin = 0, end = 0;
    std::array<std::uint32_t, Dim> first{};  // anchor of the range's first leaf
  };
  // Many more chunks than threads, taken dynamically: refinement is concentrated near the
  // boundary, so equal item counts are far from equal work.
  const std::size_t n_chunks = n_threads == 1 ? std::min<std::size_t>(n_work, 1)
                                              : std::min(n_work, std::size_t(n_threads) * 64);
  std::vector<Range> ranges(n_chunks);
  std::vector<std::exception_ptr> errors(n_chunks);
  std::atomic<std::size_t> next{0};
  run_on_threads(n_threads, [&](int t) {
    LevelSpool& out = spools[std::size_t(t)];
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= n_chunks || budget.stop) return;
      Range& range = ranges[k];
      range = {t, out.size(), out.size(), {}};
      try {
        Emitter<Dim> e(out, budget);
        for (std::size_t i = n_work * k / n_chunks, end = n_work * (k + 1) / n_chunks; i < end; ++i) work(i, e);
        e.flush();
        range.first = e.first();
      } catch (...) {
        errors[k] = std::current_exception();
        budget.stop = true;
      }
      range.end = out.size();
    }
  });
  // The first refusal that exceeded the budget carries the estimate; prefer it over the
  // "stopped" notes of the other chunks.
  std::exception_ptr first_error;
  for (const auto& err : errors) {
    if (!err) continue;
    try {
      std::rethrow_exception(err);
    } catch (const LimitError& le) {
      if (std::string(le.what()).rfind("refinement would", 0) == 0) throw;
      if (!first_error) first_error = err;
    } catch (...) {
      throw;
    }
  }
  if (first_error) std::rethrow_exception(first_error);

  std::vector<std::size_t> offset(n_chunks + 1, 0);
  for (std::size_t k = 0; k < n_chunks; ++k) offset[k + 1] = offset[k] + (ranges[k].end - ranges[k].begin);
  const std::size_t total = offset[n_chunks];
  LeafVector<Dim> out;
  out.resize(total);  // sized, not written (LeafAllocator): the threads write each cell once
  Cell<Dim>* const cells = out.data();
  for (auto& spool : spools) spool.seal();
  // The threads take chunks in order, dynamically like the expansion, and write each where
  // the counts put it, whichever spool holds it: a thread slowed by another process then does
  // less, where fixed equal shares would make the other thread wait for it.
  next = 0;
  run_on_threads(n_threads, [&](int) {
    for (std::size_t k; (k = next.fetch_add(1)) < n_chunks;) {
      const Range& r = ranges[k];
      Cell<Dim>* dst = cells + offset[k];
      std::uint64_t key = detail::interleave<Dim>(r.first);
      spools[std::size_t(r.spool)].consume(r.begin, r.end, [&](std::uint8_t level) {
        Cell<Dim> c;
        c.anchor = detail::deinterleave<Dim>(key);
        c.level = level;
        ::new (static_cast<void*>(dst++)) Cell<Dim>(c);
        key += volume_of_level<Dim>(level);
      });
    }
  });
  return out;
}

/// Expands `items` in order with `rule`.
template <int Dim, class Rule>
LeafVector<Dim> expand_items(const std::vector<Item<Dim>>& items, const Rule& rule,
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
    const std::size_t wanted = std::size_t(opt.n_threads) * 256;
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
  LeafVector<Dim> out;
  out.reserve(t.n_leaves() + n_flagged * (Cube<Dim>::n_children - 1));
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
