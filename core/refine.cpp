// Refinement: the paper's check_and_subdivide_quadrant, refinement by flags and by predicate.
// Leaves are emitted by depth-first recursion, which visits children in Morton order, so the
// output is sorted without a sort. Parallel runs split the work into an ordered list of subtrees
// (the paper: "one processor can subdivide a quadrant and send them to four processors"), expand
// them independently and concatenate in order, so any thread count gives the serial result.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/error.hpp"
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

/// Appends leaves to one output vector and reports to the budget every few thousand leaves, so
/// that memory stays bounded by max_leaves plus one batch per thread.
template <int Dim> class Emitter {
 public:
  Emitter(std::vector<Cell<Dim>>& out, Budget& budget) : out_(out), budget_(budget) {}

  void emit(const Cell<Dim>& c) {
    out_.push_back(c);
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
  std::vector<Cell<Dim>>& out_;
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

/// Expands `items` in order with `rule` on n_threads threads; the result does not depend on the
/// thread count because each contiguous chunk writes its own vector and chunks are concatenated.
template <int Dim, class Rule>
std::vector<Cell<Dim>> expand_items(const std::vector<Item<Dim>>& items, const Rule& rule,
                                    Budget& budget, int n_threads) {
  const auto process = [&](std::size_t begin, std::size_t end, std::vector<Cell<Dim>>& out) {
    Emitter<Dim> e(out, budget);
    for (std::size_t k = begin; k < end; ++k) {
      if (items[k].expand) {
        rule.run(items[k].cell, e);
      } else {
        e.emit(items[k].cell);
      }
    }
    e.flush();
  };
  if (n_threads <= 1 || items.size() <= 1) {
    std::vector<Cell<Dim>> out;
    process(0, items.size(), out);
    return out;
  }
  // Many more chunks than threads, taken dynamically: refinement is concentrated near the
  // boundary, so equal item counts are far from equal work.
  const std::size_t n_chunks = std::min(items.size(), std::size_t(n_threads) * 16);
  std::vector<std::vector<Cell<Dim>>> outs(n_chunks);
  std::vector<std::exception_ptr> errors(n_chunks);
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= n_chunks || budget.stop) return;
      try {
        process(items.size() * k / n_chunks, items.size() * (k + 1) / n_chunks, outs[k]);
      } catch (...) {
        errors[k] = std::current_exception();
        budget.stop = true;
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < n_threads; ++t) threads.emplace_back(worker);
  worker();
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
  std::size_t total = 0;
  for (const auto& o : outs) total += o.size();
  std::vector<Cell<Dim>> out;
  out.reserve(total);
  for (auto& o : outs) {
    out.insert(out.end(), o.begin(), o.end());
    std::vector<Cell<Dim>>().swap(o);
  }
  return out;
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
  std::vector<Item<Dim>> items;
  items.reserve(t.n_leaves());
  for (const auto& c : t.leaves()) items.push_back({c, true});
  return Orthtree<Dim>(t.root_box(), expand_items(items, rule, budget, opt.n_threads));
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
