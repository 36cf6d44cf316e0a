#pragma once
// glibc's malloc on transparent huge pages, one arena, for the whole process (issue 8).

#include <optional>
#include <string>

namespace febemesh {

/// The GLIBC_TUNABLES value that adds glibc.malloc.hugetlb=1 (malloc advises transparent huge
/// pages on the memory it takes from the kernel, heap and mapped blocks alike) to `current`
/// (the variable's value, null when unset), and glibc.malloc.arena_max=1 (one arena for all
/// threads) unless `current` sets an arena count; nullopt when `current` sets hugetlb already,
/// to whatever value.
std::optional<std::string> tunables_with_huge_page_heap(const char* current);

/// Runs the program again, in the same process (/proc/self/exe, the same arguments), with
/// tunables_with_huge_page_heap in its environment, and returns only when it does not: the
/// tunable is set already (this is the second start), FEBEMESH_HUGE_PAGES=0, the kernel has
/// transparent huge pages off, the C library is not glibc, the process runs under valgrind or
/// was started through the dynamic loader (ld.so PROGRAM), or the exec fails. Call it first
/// thing in main.
///
/// Why: the 2D pipeline's arrays under 32 MiB live in malloc's heap (dim2/heap_policy), which
/// glibc grows by 4 KiB pages; on this VM a 4 KiB fault costs ~11 us (3 s a GiB touched against
/// 0.06 s with 2 MiB pages, measured), and they were most of the system time of a run.
/// GLIBC_TUNABLES is read only when the C library starts, so it cannot be set from inside.
void reexec_with_huge_page_heap(char** argv);

}  // namespace febemesh
