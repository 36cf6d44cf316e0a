#pragma once
// What compare2d and compare3d write besides the meshes: comparison.json, a side-by-side
// comparison.md, and SVG histograms with one bar series per tool, all from the same numbers.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace febemesh::cli {

/// One series of values per tool, e.g. {"febemesh", angles}, {"gmsh", angles}.
using Series = std::vector<std::pair<std::string, std::vector<double>>>;

/// Histogram of each series on [lo, hi] in `n_bins` bins (values outside are clamped into the
/// end bins), as fractions of the series' size so tools with different counts compare.
void write_histogram_svg(const std::filesystem::path& path, const std::string& title, const std::string& x_label,
                         double lo, double hi, int n_bins, const Series& series);

/// Markdown table: one row per key of `keys`, one column per tool object of `comparison`.
/// A tool whose "ok" is false shows its "error" under the table.
std::string comparison_markdown(const std::string& title, const nlohmann::ordered_json& comparison,
                                const std::vector<std::string>& tools, const std::vector<std::string>& keys);

/// Writes `text` to `path`; InputError when it cannot.
void write_text(const std::filesystem::path& path, const std::string& text);

}  // namespace febemesh::cli
