#pragma once
// --size H, the cells' side at the boundary instead of --level (mesh2d, mesh3d, compare2d,
// compare3d): its value, and the level it gives on an input (core/sized_level.hpp), refused as
// bad usage past the command's finest level.

#include <sstream>
#include <string>

#include "cli/args.hpp"
#include "core/error.hpp"
#include "core/sized_level.hpp"

namespace febemesh::cli {

/// --size's value, 0 when it is not given; with --level as well, bad usage.
inline double size_option(const Args& args) {
  if (!args.has("--size")) return 0.0;
  if (args.has("--level")) throw UsageError("--size and --level: give one of them");
  return args.real_or("--size", 0.0, 1e-300, 1e300);
}

/// The level and root scale --size gives on `input` (bounding box `box`); past `finest`, bad
/// usage naming the smallest size that level allows.
template <int Dim>
SizedLevel sized_level(const Box<Dim>& box, double size, int finest, const std::string& input) {
  const SizedLevel sl = level_for_size<Dim>(box, size);
  if (sl.level > finest) {
    const double side = default_root_side(box);
    std::ostringstream os;
    os << "--size " << size << " on " << input << " (root " << side << " across) needs level " << sl.level
       << "; the finest is " << finest << ", cells of " << side / static_cast<double>(1LL << finest) << " or more";
    throw UsageError(os.str());
  }
  return sl;
}

}  // namespace febemesh::cli
