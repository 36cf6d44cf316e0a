#pragma once
// Two kinds of failure (STYLE.md §8): programmer errors assert in Debug builds;
// bad input and failed geometry throw with context.

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace febemesh {

/// Bad input: the message names the file and the place; the CLI exits with status 1.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A request that would exhaust memory or time (too deep a level, too many cells); exit status 1.
class LimitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The geometry defeated an algorithm (e.g. no admissible projection); exit status 1.
class GeometryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace febemesh

#ifdef NDEBUG
#define MESH_ASSERT(cond, msg) ((void)0)
#else
#define MESH_ASSERT(cond, msg)                                                             \
  do {                                                                                     \
    if (!(cond)) {                                                                         \
      std::ostringstream mesh_assert_os_;                                                  \
      mesh_assert_os_ << msg;                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": assertion `" #cond "` failed: "       \
                << mesh_assert_os_.str() << std::endl;                                     \
      std::abort();                                                                        \
    }                                                                                      \
  } while (0)
#endif
