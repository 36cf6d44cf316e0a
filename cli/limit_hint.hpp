#pragma once
// What a refusal for the tree's size says on the command line: the core's message names its
// option (Orthtree's max_leaves, the pipelines' max_cells), the commands' flag is --max-cells.

#include <string>

#include "core/error.hpp"

namespace febemesh::cli {

/// A LimitError's message for `input`: the file first, then the reason, and where the reason is
/// the tree's size (the core's "max_leaves = N"), the flag that raises it.
inline LimitError limit_refusal(const std::string& input, const LimitError& e) {
  std::string what = input + ": " + e.what();
  if (what.find("max_leaves = ") != std::string::npos)
    what += " (--max-cells N sets the limit; the peak memory grows with it)";
  return LimitError(what);
}

}  // namespace febemesh::cli
