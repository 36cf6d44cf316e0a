#pragma once
// SVG input (DESIGN.md contracts): every <path>, <rect>, <circle>, <ellipse>, <polygon> and
// <polyline> outside <defs>-like containers is a filled shape, whatever its fill or stroke paint,
// since a geometry file draws the solid. Transforms on elements and groups apply; `fill-rule`
// (attribute or style, inherited) decides which regions of each shape are solid. Loops come out
// in mesh coordinates (x, -y) of the user units, unscaled, oriented with the solid on their left
// (outer boundaries counter-clockwise, holes clockwise); loops that bound no solid are dropped.

#include <string>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// Relative tolerance (of the drawing's size: the diagonal of its control points' box) to which
/// elliptical arcs are approximated by cubics. Everything else is converted exactly.
inline constexpr double svg_arc_tolerance = 1e-9;

/// Parses SVG text; `source` names it in messages. Throws InputError "SOURCE:LINE:COL: reason".
Domain parse_svg(const std::string& text, const std::string& source);

/// Reads an SVG file (InputError when unreadable).
Domain read_svg(const std::string& path);

}  // namespace febemesh::dim2
