#pragma once
// Independent work over [0, n) on several threads (issue 8): the caller and n_threads - 1 more
// threads each take one contiguous range and write only their own slots, so the result does
// not depend on the thread count. A reduction whose rounding depends on the order (a sum of
// doubles) goes through fixed chunks (for_each_chunk) whose partial results the caller combines
// in chunk order: the same numbers for every thread count.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <limits>
#include <vector>

#include "core/worker_pool.hpp"

namespace febemesh {

/// Calls f(begin, end) on n_threads contiguous ranges covering [0, n) (one range when n is small
/// or n_threads is 1), the first on the calling thread (the others on run_on_threads' threads);
/// rethrows the first range's exception once all have stopped.
template <class F> void for_each_range(std::size_t n, int n_threads, const F& f) {
  const std::size_t n_workers = std::size_t(std::clamp(n_threads, 1, 256));
  if (n_workers == 1 || n < 2 * n_workers) {
    f(std::size_t{0}, n);
    return;
  }
  run_on_threads(static_cast<int>(n_workers), [&](int t) {
    const auto w = static_cast<std::size_t>(t);
    f(n * w / n_workers, n * (w + 1) / n_workers);
  });
}

/// The chunks [c * chunk, min(n, (c + 1) * chunk)) of [0, n): f(c, begin, end) for every chunk c,
/// spread over n_threads in contiguous runs of chunks, one run a thread (at most one thread a
/// chunk). The chunks do not depend on n_threads. (A chunk is its caller's unit of work: through
/// for_each_range's rule, fewer than two items a worker on one thread, a call with a chunk a
/// thread ran serially: the smoothing's slab histogram, range_max.)
template <class F> void for_each_chunk(std::size_t n, std::size_t chunk, int n_threads, const F& f) {
  const std::size_t n_chunks = (n + chunk - 1) / chunk;
  const std::size_t n_workers = std::min<std::size_t>(std::size_t(std::clamp(n_threads, 1, 256)), std::max<std::size_t>(n_chunks, 1));
  const auto run = [&](std::size_t first, std::size_t last) {
    for (std::size_t c = first; c < last; ++c) f(c, c * chunk, std::min(n, (c + 1) * chunk));
  };
  if (n_workers == 1) return run(0, n_chunks);
  // Worker w gets items [2w, 2w + 2) of for_each_range's 2 n_workers: its run of chunks.
  for_each_range(2 * n_workers, static_cast<int>(n_workers), [&](std::size_t item, std::size_t) {
    const std::size_t w = item / 2;
    run(n_chunks * w / n_workers, n_chunks * (w + 1) / n_workers);
  });
}

/// Work over [0, n) whose cost varies along it (the mesh's nodes: interior ones first, surface
/// ones last), in chunks of `chunk` handed to the threads as they come free: worker(next) runs
/// once on each of n_threads threads (the first the caller), and next(begin, end) gives it its
/// next chunk, false when none is left. Each chunk must write only its own results: which
/// thread takes which chunk varies from run to run. (Contiguous ranges, for_each_range, left
/// one of two threads idle for 0.05 s of the 3D smoothing's node lists, sphere966 L6.)
template <class Worker> void for_each_chunk_balanced(std::size_t n, std::size_t chunk, int n_threads, const Worker& worker) {
  const std::size_t n_chunks = (n + chunk - 1) / chunk;
  std::atomic<std::size_t> taken{0};
  const auto next = [&](std::size_t& begin, std::size_t& end) {
    const std::size_t c = taken.fetch_add(1, std::memory_order_relaxed);
    if (c >= n_chunks) return false;
    begin = c * chunk, end = std::min(n, (c + 1) * chunk);
    return true;
  };
  const std::size_t n_workers = std::min<std::size_t>(std::size_t(std::clamp(n_threads, 1, 256)), std::max<std::size_t>(n_chunks, 1));
  // One range a worker (for_each_range runs one range below two items a worker).
  if (n_workers == 1) return worker(next);
  for_each_range(2 * n_workers, static_cast<int>(n_workers), [&](std::size_t, std::size_t) { worker(next); });
}

/// A chunk size for for_each_chunk over [0, n): about four chunks a thread, at least min_chunk.
inline std::size_t chunk_size(std::size_t n, int n_threads, std::size_t min_chunk) {
  const std::size_t n_chunks = 4 * static_cast<std::size_t>(std::clamp(n_threads, 1, 256));
  return std::max<std::size_t>(std::max<std::size_t>(min_chunk, 1), (n + n_chunks - 1) / n_chunks);
}

/// Where each chunk of for_each_chunk(n, chunk, ...) starts writing when chunk c writes
/// count(begin, end) items (a T with +=) after those of the chunks before it, from `first`: the
/// serial loop's layout, so that the chunks can then be written at once. n_chunks + 1 entries,
/// the last the end; the counts run on n_threads threads, the same layout for every count.
template <class T, class Count>
std::vector<T> chunk_starts(std::size_t n, std::size_t chunk, int n_threads, const T& first, const Count& count) {
  const std::size_t n_chunks = (n + chunk - 1) / chunk;
  std::vector<T> start(n_chunks + 1, T{});
  for_each_chunk(n, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) { start[c + 1] = count(begin, end); });
  start[0] = first;
  for (std::size_t c = 0; c < n_chunks; ++c) start[c + 1] += start[c];
  return start;
}

/// The largest f(i) over [0, n) (-infinity when n is 0; a NaN never wins), on n_threads
/// threads: a maximum is exact in any order, so the same value for every count.
template <class F> double range_max(std::size_t n, int n_threads, const F& f) {
  const std::size_t n_parts = std::size_t(std::clamp(n_threads, 1, 256));
  std::vector<double> best(n_parts, -std::numeric_limits<double>::infinity());
  for_each_chunk(n, std::max<std::size_t>(1, (n + n_parts - 1) / n_parts), n_threads,
                 [&](std::size_t c, std::size_t begin, std::size_t end) {
                   double m = -std::numeric_limits<double>::infinity();
                   for (std::size_t i = begin; i < end; ++i) m = std::max(m, static_cast<double>(f(i)));
                   best[c] = m;
                 });
  return *std::max_element(best.begin(), best.end());
}

/// The smallest f(i) over [0, n) (+infinity when n is 0; a NaN never wins), as range_max.
template <class F> double range_min(std::size_t n, int n_threads, const F& f) {
  return -range_max(n, n_threads, [&](std::size_t i) { return -static_cast<double>(f(i)); });
}

}  // namespace febemesh
