#pragma once
// Gauss-Seidel node sweeps on several threads in a fixed order of their own (issue 8).
//
// ordered_sweep.hpp keeps the mesh's node order and lets a node go once its lower neighbours
// are done; in 2D a visit costs less than its place in that DAG (the 2D sweeps ran on one
// thread). Here the order is changed instead, the same for every thread count: the nodes are
// cut into parts, slabs along the first axis holding about as many nodes each (slab_parts). A
// node all of whose elements have every node in its own part is an inner node of that part;
// the others are separators. A sweep visits part 0's inner nodes in ascending order, then part
// 1's, ..., then the separators in ascending order. Inner nodes of two parts share no element,
// so the parts' inner nodes can be visited at once, a part per thread at a time, and every
// visit reads the numbers it reads in that order: the result of the order, bit for bit, on any
// thread count (one thread runs the same order).
//
// A visit of v may read and write v and its elements' states, read the nodes of its elements
// and write flags of those nodes only with a value every writer writes (mark(), e.g. "moved
// since"): a separator may be a node of elements of two parts' inner nodes. Scratch marks over
// all nodes (e.g. a neighbour list's "listed") must be per thread for the same reason.

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh.hpp"
#include "core/ordered_sweep.hpp"  // mark()
#include "core/parallel_ranges.hpp"
#include "core/worker_pool.hpp"

namespace febemesh {

/// The default number of parts: enough for two threads to share the work when the parts'
/// costs differ (they are cut by node count, the work sits near the boundary), few enough that
/// the separators stay a small share (each cut holds a line of nodes on both of its sides).
inline constexpr int default_sweep_parts = 16;

/// Each node's part, 0 .. n_parts - 1: slabs along the first axis with about equal node counts,
/// cut at the edges of a 256-bin histogram of the first coordinate over its range (no sort;
/// integer counts, so the same parts for every thread count). All in part 0 when the range is
/// empty or not finite.
template <int Dim>
std::vector<std::uint8_t> slab_parts(const std::vector<Point<Dim>>& points, int n_parts, int n_threads) {
  const std::size_t n = points.size();
  std::vector<std::uint8_t> part(n, 0);
  n_parts = std::clamp(n_parts, 1, 255);
  if (n_parts == 1 || n == 0) return part;
  const double lo = range_min(n, n_threads, [&](std::size_t v) { return points[v][0]; });
  const double hi = range_max(n, n_threads, [&](std::size_t v) { return points[v][0]; });
  if (!(std::isfinite(lo) && std::isfinite(hi) && hi > lo)) return part;
  // Each node's bin first (in `part`), counted per range; then bins -> parts in place.
  constexpr int n_bins = 256;
  const double scale = n_bins / (hi - lo);
  const std::size_t n_ranges = static_cast<std::size_t>(std::clamp(n_threads, 1, 256));
  std::vector<std::array<std::size_t, n_bins>> counts(n_ranges);
  for_each_chunk(n, (n + n_ranges - 1) / n_ranges, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    std::array<std::size_t, n_bins>& count = counts[c];
    count.fill(0);
    for (std::size_t v = begin; v < end; ++v) {
      const double b = (points[v][0] - lo) * scale;
      const auto bin = static_cast<std::uint8_t>(b >= 0 ? std::min(n_bins - 1, static_cast<int>(b)) : 0);  // (NaN: 0)
      part[v] = bin;
      ++count[bin];
    }
  });
  // Bin b goes to part floor(nodes before the bin's middle * n_parts / n).
  std::array<std::uint8_t, n_bins> part_of_bin{};
  std::size_t before = 0;
  for (std::size_t b = 0; b < n_bins; ++b) {
    std::size_t in_bin = 0;
    for (const auto& count : counts) in_bin += count[b];
    part_of_bin[b] = static_cast<std::uint8_t>(std::min<std::size_t>(n_parts - 1, (before + in_bin / 2) * n_parts / n));
    before += in_bin;
  }
  for_each_range(n, n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) part[v] = part_of_bin[part[v]];
  });
  return part;
}

/// Whether each node is a separator of `part` in `els`: a node of an element whose nodes lie
/// in two parts or more (1), else 0. Elements on n_threads threads (the flags do not depend on
/// the count).
inline std::vector<std::uint8_t> separators(std::span<const std::uint8_t> part, const Elements& els, int n_threads) {
  std::vector<std::uint8_t> sep(part.size(), 0);
  for_each_range(els.size(), n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) {
      const VertexId* v = els.node.data() + els.offset[e];
      const int k = els.offset[e + 1] - els.offset[e];
      bool split = false;
      for (int i = 1; i < k && !split; ++i) split = part[static_cast<std::size_t>(v[i].v)] != part[static_cast<std::size_t>(v[0].v)];
      if (split)
        for (int i = 0; i < k; ++i) mark(sep[static_cast<std::size_t>(v[i].v)], 1);
    }
  });
  return sep;
}

/// A sweep over some of the nodes in the order of the file comment, run on n_threads threads.
class PartitionedSweep {
 public:
  /// The nodes v of [0, part.size()) with keep(v), in the order: each part's inner nodes
  /// ascending, part by part, then the separators ascending.
  template <class Keep>
  PartitionedSweep(std::span<const std::uint8_t> part, int n_parts, std::span<const std::uint8_t> separator,
                   const Keep& keep, int n_threads)
      : n_threads_(std::max(1, n_threads)) {
    n_parts = std::clamp(n_parts, 1, 255);
    const std::size_t n = part.size();
    start_.assign(static_cast<std::size_t>(n_parts) + 2, 0);
    const auto group = [&](std::size_t v) { return separator[v] ? n_parts : static_cast<int>(part[v]); };
    for (std::size_t v = 0; v < n; ++v)
      if (keep(static_cast<std::int32_t>(v))) ++start_[static_cast<std::size_t>(group(v)) + 1];
    for (std::size_t g = 0; g + 1 < start_.size(); ++g) start_[g + 1] += start_[g];
    order_.resize(start_.back());
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t v = 0; v < n; ++v)
      if (keep(static_cast<std::int32_t>(v))) order_[fill[static_cast<std::size_t>(group(v))]++] = static_cast<std::int32_t>(v);
  }

  int n_threads() const { return n_threads_; }
  int n_parts() const { return static_cast<int>(start_.size()) - 2; }
  /// The whole order (what one thread visits, in turn).
  std::span<const std::int32_t> order() const { return order_; }
  /// The separators, at the end of the order.
  std::size_t n_separators() const { return start_.back() - start_[start_.size() - 2]; }

  /// visit(v, t) for every node of the order but those with skip(v) (asked just before the
  /// node's turn), with the result of visiting them in the order; t is the thread (0 = the
  /// caller). The parts' inner nodes on n_threads threads (a part to a thread that is free, in
  /// part order), then between() on the caller, then the separators on the caller. Rethrows
  /// the first exception (of the lowest thread) once every thread has stopped.
  template <class Visit, class Between, class Skip> void run(const Visit& visit, const Between& between, const Skip& skip) const {
    // visit is called from this one place (so that it can be inlined here).
    const auto visit_groups = [&](std::size_t first, std::size_t last, int t) {
      for (std::size_t i = start_[first]; i < start_[last]; ++i)
        if (!skip(order_[i])) visit(order_[i], t);
    };
    const std::size_t n_groups = start_.size() - 2;
    const int n_workers = std::min<int>(n_threads_, static_cast<int>(n_groups));
    if (n_workers <= 1) {
      visit_groups(0, n_groups, 0);
    } else {
      std::atomic<std::size_t> next{0};
      run_on_threads(n_workers, [&](int t) {
        try {
          for (std::size_t g; (g = next.fetch_add(1, std::memory_order_relaxed)) < n_groups;) visit_groups(g, g + 1, t);
        } catch (...) {
          next.store(n_groups, std::memory_order_relaxed);  // the others stop after their part
          throw;
        }
      });
    }
    between();
    visit_groups(n_groups, n_groups + 1, 0);
  }
  template <class Visit, class Between> void run(const Visit& visit, const Between& between) const {
    run(visit, between, [](std::int32_t) { return false; });
  }
  template <class Visit> void run(const Visit& visit) const {
    run(visit, [] {});
  }

 private:
  int n_threads_ = 1;
  std::vector<std::size_t> start_;  ///< group g's nodes: order_[start_[g], start_[g + 1]); the last group the separators
  std::vector<std::int32_t> order_;
};

}  // namespace febemesh
