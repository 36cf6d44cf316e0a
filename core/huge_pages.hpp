#pragma once
// Transparent huge pages for large, freshly reserved arrays (the tree's leaves).

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include <sys/mman.h>

#include "core/parallel_ranges.hpp"

namespace febemesh {

/// Whether huge pages are wanted: FEBEMESH_HUGE_PAGES=1 in the environment (read once). Off by
/// default: on the Firecracker VM of sessions 25-26 (free page reporting to the host, THP defrag
/// on madvise) a fresh 2 MiB page's first touch cost ~20x a 4 KiB page's (512 MB touched once
/// after a pause: 102-145 MB/s advised, 2.4-2.8 GB/s not), and the advised arrays of a 3D run
/// were faulted in serial stretches of 0.1-0.3 s (perf, sphere966 L6 on two threads).
inline bool huge_pages_wanted() {
  static const bool wanted = [] {
    const char* v = std::getenv("FEBEMESH_HUGE_PAGES");
    return v != nullptr && std::strcmp(v, "1") == 0;
  }();
  return wanted;
}

/// Whether malloc's memory should come on transparent huge pages (the restart of
/// core/huge_page_heap.hpp's set_up_heap): on unless FEBEMESH_HUGE_PAGES=0 (read once); the
/// large arrays' own advice (huge_pages_wanted) stays off unless FEBEMESH_HUGE_PAGES=1. On since
/// session 41, when this VM ran faster with it (sessions 25-40: off, when it ran slower):
/// bench_mesh2d flange 10^6, one thread, eleven alternating rounds, faster in ten (0.464-0.695 s
/// against 0.601-0.873; in the quietest three 0.476-0.517 against 0.614-0.631); bench_mesh3d
/// sphere966 at 4,941,815 tets 11.4-12.8 s against 14.7-17.4 (peak 493.9-519.1 against
/// 478.1-535.3 MB), at 995,249 2.92-3.98 against 3.12-4.62 s (the quietest three 2.92-3.08
/// against 3.23-3.27; peak 104.9-107.1 against 101.8-101.9 MB). The same meshes.
inline bool huge_page_heap_wanted() {
  static const bool wanted = [] {
    const char* v = std::getenv("FEBEMESH_HUGE_PAGES");
    return v == nullptr || std::strcmp(v, "0") != 0;
  }();
  return wanted;
}

/// The part [lo, hi) of [p, p + bytes) aligned to `align` (a power of two) at both ends; empty
/// (hi <= lo) where there is none.
inline std::pair<std::uintptr_t, std::uintptr_t> aligned_part(const void* p, std::size_t bytes, std::uintptr_t align) {
  return {(reinterpret_cast<std::uintptr_t>(p) + align - 1) & ~(align - 1),
          (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(align - 1)};
}

/// madvise(advice) on the aligned part of [p, p + bytes) (aligned_part), where there is one.
/// Advice only: errors are ignored.
inline void advise_aligned(const void* p, std::size_t bytes, std::uintptr_t align, int advice) {
  const auto [lo, hi] = aligned_part(p, bytes, align);
  if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, advice);
}

/// Asks for transparent huge pages on the 2 MiB-aligned part of [p, p + bytes). Page faults and
/// their zeroing are a large part of writing millions of leaves (measured: refinement spends a
/// third of its time in the kernel with 4 KiB pages), and a 2 MiB page costs one fault instead
/// of 512. Call it before the pages are first touched. Advice only: ignored where the kernel
/// does not support it, and the resident set grows by at most one partly used huge page. Only
/// when huge_pages_wanted().
inline void advise_huge_pages(const void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  if (!huge_pages_wanted()) return;
  advise_aligned(p, bytes, std::uintptr_t(1) << 21, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

/// Backs the whole pages of [p, p + bytes) now (MADV_POPULATE_WRITE, Linux 5.14; nothing where
/// the kernel lacks it), in one call instead of a page fault at each page's first write. On this
/// machine (a guest whose first write to a fresh 4 KiB page is slow) 64 MB written fresh took
/// 184-196 ms, populated first 12-15 ms + 90-92 ms; bench_mesh2d flange at 10^6 triangles, one
/// thread, six rounds: 0.680-0.960 s (median 0.73) against 0.780-1.060 s (median 0.93), system
/// time 0.10-0.15 s against 0.26-0.34 s. Populated pages are resident: only for storage that will
/// be written.
inline void populate_pages(const void* p, std::size_t bytes) {
#ifndef MADV_POPULATE_WRITE
  constexpr int populate_write = 23;  // (glibc's headers before 2.35)
#else
  constexpr int populate_write = MADV_POPULATE_WRITE;
#endif
  advise_aligned(p, bytes, 4096, populate_write);
}

/// v.reserve(n), with huge pages on fresh storage of 4 MiB or more (below, the one partly used
/// huge page at each end would be a visible share of it, as for the tree's leaves), and no
/// populating: for room that may stay unwritten (an upper bound on the elements).
template <class T, class A> void reserve_room(std::vector<T, A>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.reserve(n);
  if (n * sizeof(T) >= (std::size_t(4) << 20)) advise_huge_pages(v.data(), n * sizeof(T));
}

/// Populates the whole pages of [p, p + bytes) (populate_pages) and writes a zero byte to each
/// of them, on n_threads threads, each over its own range of pages. For fresh storage that is
/// about to be written on one thread (a vector's resize or assign, which value-initializes it):
/// on this machine a fresh page's first write costs far more than the write itself, even after
/// MADV_POPULATE_WRITE (64 MB, one thread: populated in 11 ms, then written in 82-87 ms, and
/// again in 3 ms; on two threads 53 ms), so the first writes are better shared out. The bytes
/// are storage no object lives in yet (the caller constructs its elements after this).
inline void touch_pages(void* p, std::size_t bytes, int n_threads) {
  constexpr std::size_t page = 4096;
  const auto [lo, hi] = aligned_part(p, bytes, page);
  if (hi <= lo) return;
  for_each_range((hi - lo) / page, n_threads, [&](std::size_t begin, std::size_t end) {
    auto* first = reinterpret_cast<unsigned char*>(lo + begin * page);
    populate_pages(first, (end - begin) * page);
    for (std::size_t k = 0; k < end - begin; ++k) *static_cast<volatile unsigned char*>(first + k * page) = 0;
  });
}

/// reserve_room(v, n) for n elements that will all be written (assign, resize, or n push_backs
/// after it): fresh storage of 1 MiB or more is populated (populate_pages), and with n_threads
/// > 1 fresh storage of 4 MiB or more is first written on that many threads (touch_pages):
/// value-initializing it in resize was the largest serial part of the 2D pipeline on two
/// threads (perf, flange at 10^6 triangles: memset 14% of the main thread's samples, none on
/// the other).
/// Only the room past v's elements is touched (the elements it holds are moved there intact).
template <class T, class A> void reserve_huge(std::vector<T, A>& v, std::size_t n, int n_threads = 1) {
  if (v.capacity() >= n) return;
  reserve_room(v, n);
  void* const room = v.data() + v.size();
  const std::size_t bytes = (n - v.size()) * sizeof(T);
  if (n_threads > 1 && bytes >= (std::size_t(4) << 20)) touch_pages(room, bytes, n_threads);
  else if (bytes >= (std::size_t(1) << 20)) populate_pages(room, bytes);
}

}  // namespace febemesh
