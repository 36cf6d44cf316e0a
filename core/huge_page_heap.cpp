#include "core/huge_page_heap.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc
#include <fstream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sys/auxv.h>
#include <unistd.h>

#include "core/huge_pages.hpp"

#if __has_include(<valgrind/valgrind.h>)
#include <valgrind/valgrind.h>
#endif

namespace febemesh {

bool tunable_is_set(const char* tunables, const std::string& name) {
  const std::string now = tunables ? tunables : "";
  // Entries are name=value, separated by ':'.
  for (std::size_t begin = 0; begin <= now.size();) {
    std::size_t end = now.find(':', begin);
    if (end == std::string::npos) end = now.size();
    if (now.compare(begin, name.size() + 1, name + "=") == 0) return true;
    begin = end + 1;
  }
  return false;
}

std::optional<std::string> tunables_with_huge_page_heap(const char* current) {
  if (tunable_is_set(current, "glibc.malloc.hugetlb")) return std::nullopt;
  std::string out = current ? current : "";
  const auto add = [&](const std::string& entry) { out += (out.empty() ? "" : ":") + entry; };
  if (!tunable_is_set(current, "glibc.malloc.arena_max")) add("glibc.malloc.arena_max=1");
  add("glibc.malloc.hugetlb=1");
  return out;
}

namespace {

bool kernel_has_huge_pages() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  return std::getline(in, modes) && modes.find("[never]") == std::string::npos;
}

/// The program was started through the dynamic loader (ld.so PROGRAM ...): the kernel then ran
/// ld.so itself, with no interpreter (AT_BASE 0), and /proc/self/exe is ld.so, which would take
/// the first argument for the program to run.
bool started_by_loader() {
#ifdef AT_BASE
  return getauxval(AT_BASE) == 0;
#else
  return true;
#endif
}

bool under_valgrind() {
#ifdef RUNNING_ON_VALGRIND
  return RUNNING_ON_VALGRIND != 0;  // its tools would lose the program at the exec
#else
  return false;
#endif
}

}  // namespace

void reexec_with_huge_page_heap(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  const char* before = std::getenv("GLIBC_TUNABLES");
  const std::optional<std::string> tunables = tunables_with_huge_page_heap(before);
  if (!tunables || under_valgrind() || started_by_loader() || !kernel_has_huge_pages()) return;
  const std::optional<std::string> saved = before ? std::optional<std::string>(before) : std::nullopt;
  if (setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Still here: the exec failed; run on as started (children would inherit the tunable).
  if (saved) setenv("GLIBC_TUNABLES", saved->c_str(), 1);
  else unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

void set_up_malloc() {
#if defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (!tunable_is_set(tunables, "glibc.malloc.arena_max")) mallopt(M_ARENA_MAX, 1);
  if (!tunable_is_set(tunables, "glibc.malloc.mmap_threshold")) mallopt(M_MMAP_THRESHOLD, static_cast<int>(own_mapping_bytes));
#endif
}

void set_up_heap(char** argv) {
#if defined(__GLIBC__) && defined(__linux__)
  if (huge_page_heap_wanted()) reexec_with_huge_page_heap(argv);
#else
  (void)argv;
#endif
  set_up_malloc();
}

}  // namespace febemesh
