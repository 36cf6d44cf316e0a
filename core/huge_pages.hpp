#pragma once
// Transparent huge pages for large, freshly reserved arrays (the tree's leaves).

#include <cstddef>
#include <cstdint>
#include <vector>

#include <sys/mman.h>

namespace febemesh {

/// Asks for transparent huge pages on the 2 MiB-aligned part of [p, p + bytes). Page faults and
/// their zeroing are a large part of writing millions of leaves (measured: refinement spends a
/// third of its time in the kernel with 4 KiB pages), and a 2 MiB page costs one fault instead
/// of 512. Call it before the pages are first touched. Advice only: ignored where the kernel
/// does not support it, and the resident set grows by at most one partly used huge page.
inline void advise_huge_pages(const void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t huge = std::uintptr_t(1) << 21;
  const std::uintptr_t lo = (reinterpret_cast<std::uintptr_t>(p) + huge - 1) & ~(huge - 1);
  const std::uintptr_t hi = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(huge - 1);
  if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

/// v.reserve(n), with huge pages on fresh storage of 4 MiB or more (below, the one partly used
/// huge page at each end would be a visible share of it, as for the tree's leaves). Call it
/// before the elements are written (assign, resize or push_back after it).
template <class T, class A> void reserve_huge(std::vector<T, A>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.reserve(n);
  if (n * sizeof(T) >= (std::size_t(4) << 20)) advise_huge_pages(v.data(), n * sizeof(T));
}

}  // namespace febemesh
