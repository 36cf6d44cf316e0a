#pragma once
// Node -> item incidence lists in compressed rows, built on several threads (issue 8): each
// thread counts and then fills the items of one contiguous range, so every node's list holds its
// items in increasing order whatever the thread count (the serial lists).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/huge_pages.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

/// The items listing node v are item[start[v] .. start[v+1]), ascending, once per listing.
/// nodes_of(k, f) calls f(v) for every node v (< n) of item k; it is called from n_threads
/// threads at once. Below 65536 items, one thread.
template <class NodesOf>
void incidence_csr(std::size_t n, std::size_t n_items, const NodesOf& nodes_of, int n_threads,
                   std::vector<std::int32_t>& start, std::vector<std::int32_t>& item) {
  // Two parts a thread (for_each_range runs fewer than two chunks a thread on one thread).
  const std::size_t n_parts = n_items < 65536 || n_threads <= 1 ? 1 : 2 * static_cast<std::size_t>(std::clamp(n_threads, 1, 256));
  const std::size_t chunk = std::max<std::size_t>(1, (n_items + n_parts - 1) / n_parts);
  // cursor[c][v]: part c's count of node v's listings, then where part c writes its next one.
  std::vector<std::vector<std::int32_t>> cursor(n_parts);
  for_each_chunk(n_items, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    cursor[c].assign(n, 0);
    for (std::size_t k = begin; k < end; ++k) nodes_of(k, [&](std::int32_t v) { ++cursor[c][static_cast<std::size_t>(v)]; });
  });
  for (auto& part : cursor) part.resize(n, 0);  // parts without items
  reserve_huge(start, n + 1);
  start.assign(n + 1, 0);
  for (std::size_t v = 0; v < n; ++v) {
    std::int32_t at = start[v];
    for (auto& part : cursor) {
      const std::int32_t count = part[v];
      part[v] = at;
      at += count;
    }
    start[v + 1] = at;
  }
  reserve_huge(item, static_cast<std::size_t>(start[n]));
  item.resize(static_cast<std::size_t>(start[n]));
  for_each_chunk(n_items, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k)
      nodes_of(k, [&](std::int32_t v) { item[static_cast<std::size_t>(cursor[c][static_cast<std::size_t>(v)]++)] = static_cast<std::int32_t>(k); });
  });
}

}  // namespace febemesh
