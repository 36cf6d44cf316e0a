#pragma once
// One entry point for 2D geometry files: the format is chosen by the extension (.json native
// B-spline, .svg, .poly), or by the content when there is no extension. Every reader refuses bad
// input with InputError naming the file, the place and the reason (DESIGN.md contracts).

#include <optional>
#include <string>

#include "dim2/curve_model.hpp"
#include "dim2/xml_lite.hpp"

namespace febemesh::dim2 {

/// Reads a 2D domain from `path` (.json, .svg or .poly; case-insensitive). Unknown extension,
/// unreadable file or bad content: InputError.
Domain read_domain(const std::string& path);

/// The whole file as text; InputError "PATH: cannot read: reason" when it is missing, a
/// directory or unreadable.
std::string read_text_file(const std::string& path);

/// 1-based line and column of byte `offset` in `text` (columns count characters, not bytes).
TextPos position_of_offset(const std::string& text, std::size_t offset);

/// "SOURCE:LINE:COL: " for messages.
std::string where(const std::string& source, TextPos p);

/// "SOURCE: near (x, y): " for messages about geometry (mesh coordinates).
std::string where(const std::string& source, const P2& p);

/// The smallest loop the readers accept, across: below it its area (a product of two lengths)
/// underflows and the loop read as "zero area" (a square 1e-150 across still meshes).
inline constexpr double min_loop_extent = 1e-150;

/// For a loop whose control points' box is under min_loop_extent across, the reason to refuse
/// it: "the loop is X across, under the smallest accepted extent 1e-150 (scale the input)"; the
/// reader adds the place (built only then).
std::optional<std::string> loop_extent_problem(const Box<2>& box);

/// Refuses a mesh control parameter outside [0, 28] with the memory a full tree of that depth
/// would need (4^level cells of about 12 bytes); `place` prefixes the message.
void check_level(double level, const std::string& place);

}  // namespace febemesh::dim2
