#pragma once
// How the C library's allocator treats the 2D pipeline's large, short-lived arrays.

namespace febemesh::dim2 {

/// Keeps freed blocks of up to 32 MiB in the process heap for the next stage's arrays, instead
/// of glibc's default of returning every block above its (dynamic) mmap threshold to the kernel
/// on free: each stage of mesh2d allocates and frees arrays of this size (CSR lists, element
/// states, marks), and each fresh mapping is faulted in and zeroed again page by page; at
/// 5.4 M triangles (flange, bench_mesh2d --sizes 1e6) those faults were a fifth of the run
/// (perf: exc_page_fault, clear_page). Blocks above 32 MiB (glibc's largest mmap threshold)
/// are still mapped and unmapped, so the peak memory does not grow. Process-wide and
/// idempotent; does nothing on other C libraries.
void keep_freed_arrays_in_heap();

}  // namespace febemesh::dim2
