#pragma once
// The process's malloc: one arena, large blocks mapped on their own, and transparent huge pages
// on request (issue 8).

#include <cstddef>
#include <optional>
#include <string>

namespace febemesh {

/// Whether the GLIBC_TUNABLES value `tunables` (null when unset) sets `name`, to any value.
bool tunable_is_set(const char* tunables, const std::string& name);

/// The GLIBC_TUNABLES value that adds glibc.malloc.hugetlb=1 (malloc advises transparent huge
/// pages on the memory it takes from the kernel, heap and mapped blocks alike) to `current`
/// (the variable's value, null when unset), and glibc.malloc.arena_max=1 (one arena for all
/// threads) unless `current` sets an arena count; nullopt when `current` sets hugetlb already,
/// to whatever value.
std::optional<std::string> tunables_with_huge_page_heap(const char* current);

/// Runs the program again, in the same process (/proc/self/exe, the same arguments), with
/// tunables_with_huge_page_heap in its environment, and returns only when it does not: the
/// tunable is set already (this is the second start), the kernel has transparent huge pages
/// off, the C library is not glibc, the process runs under valgrind or was started through the
/// dynamic loader (ld.so PROGRAM), or the exec fails. A restart because glibc reads
/// GLIBC_TUNABLES only when it starts, and mallopt has no huge-page setting.
void reexec_with_huge_page_heap(char** argv);

/// Blocks of this size and more get a mapping of their own when the heap has no free room for
/// them (glibc's mmap threshold), given back to the kernel when freed. glibc's own threshold
/// rises to the largest mapped block freed (up to 32 MiB), so a mesh's per-element arrays came
/// from the heap, whose freed middle stays resident. Measured (session 44, one thread):
/// bench_mesh3d sphere966 at 995,249 tets, peak RSS growth 103.1-105.2 MB with glibc's
/// threshold, 93.7-94.0 with 8 MiB (4 MiB 93.8-96.0, 2 MiB 92.2-92.7, 1 MiB 88.9-90.8), the
/// same time; at 4,941,815 tets 465.7-472.3 -> 448.8-448.9 MB. Each fresh mapping costs page
/// faults: fandisk level 5 (CLI) spends 0.22-0.39 s in the kernel with glibc's threshold,
/// 0.29-0.35 with 8 MiB, 0.43-0.47 with 4 MiB, 1.55 with 2 MiB, 2.0 with 1 MiB. How much of the
/// freed heap stays resident still depends on what the process did before: 10^6 after 10^5 in
/// one bench run grows 104.5 MB with 8 MiB, 95.4 with 4 MiB, which is 5% slower at 10^6 alone.
inline constexpr std::size_t own_mapping_bytes = std::size_t{8} << 20;

/// On glibc, mallopt: one arena for every thread (unless GLIBC_TUNABLES sets an arena count) and
/// blocks of own_mapping_bytes and more mapped on their own (unless GLIBC_TUNABLES sets
/// glibc.malloc.mmap_threshold). Elsewhere nothing.
void set_up_malloc();

/// The process's malloc set-up; call it first thing in main: unless FEBEMESH_HUGE_PAGES=0, the
/// restart of reexec_with_huge_page_heap (huge_page_heap_wanted), then set_up_malloc.
///
/// One arena: with an arena a thread, the second thread's blocks did not reuse what the first
/// had freed (bench_mesh3d sphere966 L6 on two threads: peak 154 -> 142-144 MB, the same time).
/// Huge pages: on by default since session 41 (measured: core/huge_pages.hpp's
/// huge_page_heap_wanted); before, on the Firecracker VM of sessions 22-23 a 4 KiB page's first
/// touch cost ~11 us and the huge-page heap saved 7-8% of the 10^6-element benchmarks; on the
/// VM of session 25 (free page reporting of 8 MiB blocks to the host, THP defrag on madvise) it
/// did not pay, in interleaved pairs, one thread: bench_mesh3d sphere966 L6 slower with it in 7
/// of 7 (4.05-5.43 s wall, system 0.21-1.18 s, against 3.85-4.10 s, 0.05-0.08 s), bench_mesh2d
/// flange 1e6 in 5 of 7 (4.04-7.95 s against 3.57-5.32 s), the CLI on sphere966 L6 (which
/// also validates and writes mesh.vtu) in 3 of 7 (5.64-7.34 s against 5.88-6.82 s), so it was
/// off from session 25 to 40. FEBEMESH_HUGE_PAGES=1 also turns on reserve_huge's advice
/// (core/huge_pages.hpp; off since session 26).
void set_up_heap(char** argv);

}  // namespace febemesh
