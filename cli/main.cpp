// febemesh: one program, one subcommand per task (DESIGN.md contracts).
// Exit status: 0 success, 1 bad input (message names the file and the problem), 2 bad usage.

#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli/command.hpp"
#include "core/error.hpp"
#include "core/huge_page_heap.hpp"

#ifndef FEBEMESH_VERSION
#define FEBEMESH_VERSION "unknown"
#endif

namespace febemesh::cli {

std::map<std::string, Command>& registry() {
  static std::map<std::string, Command> commands;
  return commands;
}

namespace {

void print_overview(std::ostream& os) {
  os << "febemesh " FEBEMESH_VERSION " - finite element / boundary element mesh generation by a modified\n"
        "quadtree (2D) and octree (3D): interior cells, boundary cells built by projection onto the\n"
        "boundary, FE mesh of the solid and BE mesh of its interface sharing the same nodes.\n\n"
        "usage: febemesh COMMAND [ARGS...]\n"
        "       febemesh COMMAND --help\n"
        "       febemesh --version\n\n"
        "commands:\n";
  for (const auto& [name, c] : registry()) os << "  " << name << std::string(12 - std::min<std::size_t>(name.size(), 11), ' ') << c.summary << "\n";
  os << "\nexit status: 0 success, 1 bad input, 2 bad usage\n"
        "environment: the program starts again once with GLIBC_TUNABLES=glibc.malloc.hugetlb=1\n"
        "  (malloc on 2 MiB pages: 15-25% faster on this machine's benchmarks) unless\n"
        "  FEBEMESH_HUGE_PAGES=0 or GLIBC_TUNABLES sets the tunable; FEBEMESH_HUGE_PAGES=1 also\n"
        "  advises the large arrays (madvise); blocks of 8 MiB and more are mapped on their own\n"
        "  and given back when freed (glibc.malloc.mmap_threshold in GLIBC_TUNABLES sets another\n"
        "  size); the same meshes either way\n";
}

}  // namespace
}  // namespace febemesh::cli

int main(int argc, char** argv) {
  febemesh::set_up_heap(argv);  // first: it may start the program again
  using namespace febemesh::cli;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    print_overview(std::cerr);
    return exit_usage;
  }
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_overview(std::cout);
    return exit_ok;
  }
  if (args[0] == "--version") {
    std::cout << "febemesh " FEBEMESH_VERSION "\n";
    return exit_ok;
  }
  auto it = registry().find(args[0]);
  if (it == registry().end()) {
    std::cerr << "febemesh: unknown command '" << args[0] << "' (see febemesh --help)\n";
    return exit_usage;
  }
  const Command& cmd = it->second;
  std::vector<std::string> rest(args.begin() + 1, args.end());
  for (const auto& a : rest) {
    if (a == "--help" || a == "-h") {
      std::cout << cmd.help;
      return exit_ok;
    }
  }
  try {
    return cmd.run(rest);
  } catch (const UsageError& e) {
    std::cerr << "febemesh " << cmd.name << ": " << e.what() << " (see febemesh " << cmd.name << " --help)\n";
    return exit_usage;
  } catch (const febemesh::InputError& e) {
    std::cerr << "febemesh " << cmd.name << ": error: " << e.what() << "\n";
    return exit_bad_input;
  } catch (const febemesh::LimitError& e) {
    std::cerr << "febemesh " << cmd.name << ": refused: " << e.what() << "\n";
    return exit_bad_input;
  } catch (const febemesh::GeometryError& e) {
    std::cerr << "febemesh " << cmd.name << ": geometry error: " << e.what() << "\n";
    return exit_bad_input;
  } catch (const std::bad_alloc&) {
    std::cerr << "febemesh " << cmd.name << ": out of memory; try a lower --level\n";
    return exit_bad_input;
  } catch (const std::exception& e) {
    std::cerr << "febemesh " << cmd.name << ": internal error: " << e.what() << "\n";
    return 3;
  }
}
