#pragma once
// Triangle's .poly format (Shewchuk): vertices, segments, hole points (regional attributes are
// read and ignored). The segments must form closed simple chains; each becomes a polygon loop in
// which every vertex is a corner. Hole points are checked against the loops' nesting (which the
// curve boundary derives from the geometry): every hole point must lie in a hole, and every hole
// loop must hold a hole point, since Triangle would otherwise mesh it as solid.

#include <string>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// Parses .poly text; `source` names it in messages; `node_text` is the companion .node file's
/// text when the .poly lists zero vertices (Triangle's convention), else unused.
Domain parse_poly(const std::string& text, const std::string& source, const std::string& node_text = "",
                  const std::string& node_source = "");

/// Reads a .poly file (and FILE.node when it declares zero vertices).
Domain read_poly(const std::string& path);

}  // namespace febemesh::dim2
