#pragma once
// Subcommands of the `febemesh` program. Each lives in its own cli/cmd_*.cpp and registers
// itself with FEBEMESH_COMMAND; main() dispatches. Exit status: 0 success, 1 bad input, 2 usage.

#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace febemesh::cli {

inline constexpr int exit_ok = 0;
inline constexpr int exit_bad_input = 1;
inline constexpr int exit_usage = 2;

/// Wrong command line: printed with a hint to --help, exit status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Command {
  std::string name;
  std::string summary;  ///< one line for `febemesh --help`
  std::string help;     ///< full text for `febemesh NAME --help`
  std::function<int(const std::vector<std::string>& args)> run;
};

std::map<std::string, Command>& registry();

struct Registrar {
  explicit Registrar(Command c) { registry().emplace(c.name, std::move(c)); }
};

}  // namespace febemesh::cli

#define FEBEMESH_CONCAT2(a, b) a##b
#define FEBEMESH_CONCAT(a, b) FEBEMESH_CONCAT2(a, b)
/// Register a subcommand: FEBEMESH_COMMAND(Command{"mesh2d", "summary", "help", run});
#define FEBEMESH_COMMAND(...) \
  static ::febemesh::cli::Registrar FEBEMESH_CONCAT(febemesh_registrar_, __LINE__)(__VA_ARGS__)
