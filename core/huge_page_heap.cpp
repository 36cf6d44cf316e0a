#include "core/huge_page_heap.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc
#include <cstring>
#include <fstream>

#include <sys/auxv.h>
#include <unistd.h>

#if __has_include(<valgrind/valgrind.h>)
#include <valgrind/valgrind.h>
#endif

namespace febemesh {

std::optional<std::string> tunables_with_huge_page_heap(const char* current) {
  const std::string now = current ? current : "";
  // Entries are name=value, separated by ':'.
  const auto has = [&](const std::string& tunable) {
    for (std::size_t begin = 0; begin <= now.size();) {
      std::size_t end = now.find(':', begin);
      if (end == std::string::npos) end = now.size();
      if (now.compare(begin, tunable.size() + 1, tunable + "=") == 0) return true;
      begin = end + 1;
    }
    return false;
  };
  if (has("glibc.malloc.hugetlb")) return std::nullopt;
  std::string out = now;
  const auto add = [&](const std::string& entry) { out += (out.empty() ? "" : ":") + entry; };
  // One arena for every thread: with an arena a thread, the second thread's blocks did not
  // reuse what the first had freed (bench_mesh3d sphere966 L6 on two threads: peak 154 -> 142-144
  // MB, 104 -> 96-98 B/tet, the same wall and CPU time; flange 1e6: 496-498 -> 495 MB).
  if (!has("glibc.malloc.arena_max")) add("glibc.malloc.arena_max=1");
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
  const char* opt_out = std::getenv("FEBEMESH_HUGE_PAGES");
  if (opt_out && std::strcmp(opt_out, "0") == 0) return;
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

}  // namespace febemesh
