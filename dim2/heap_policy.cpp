#include "dim2/heap_policy.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace febemesh::dim2 {

void keep_freed_arrays_in_heap() {
#if defined(__GLIBC__)
  // Fixed settings (setting either turns glibc's dynamic threshold off): blocks below 32 MiB
  // come from the heap, and the heap's free top is kept up to 1 GiB instead of 128 KiB.
  static const bool done = [] {
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    return true;
  }();
  (void)done;
#endif
}

}  // namespace febemesh::dim2
