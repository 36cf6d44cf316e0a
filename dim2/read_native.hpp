#pragma once
// The native input (docs/native-format.md): JSON holding the paper's B-spline control points
// (simple or corner, each with an optional mesh control parameter), interior control points and
// default options. Strict: unknown keys are refused (a misspelt "corner" would silently change
// the shape), except "comment" and keys starting with '_'.

#include <optional>
#include <string>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// The native file's options beyond the Domain.
struct NativeOptions {
  std::optional<std::string> elements;  ///< "tri", "quad" or "mixed", if given
};

/// Parses native JSON text; `source` names it in messages. Throws InputError:
/// "SOURCE:LINE:COL: reason" for malformed JSON, "SOURCE: /json/pointer: reason" or
/// "SOURCE: near (x, y): reason" for bad content.
Domain parse_native(const std::string& text, const std::string& source, NativeOptions* options = nullptr);

/// Reads a native file (InputError when unreadable).
Domain read_native(const std::string& path, NativeOptions* options = nullptr);

}  // namespace febemesh::dim2
