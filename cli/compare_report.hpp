#pragma once
// What compare2d and compare3d write besides the meshes: comparison.json, a side-by-side
// comparison.md, and SVG histograms with one bar series per tool, all from the same numbers.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_output.hpp"

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

/// One histogram plot of a comparison (write_histogram_svg's arguments).
struct HistogramPlot {
  std::string file, title, x_label;
  double lo = 0.0, hi = 1.0;
  int n_bins = 20;
  Series series;  ///< one entry per tool that meshed
};

/// Everything compare2d / compare3d write and print once both tools have run.
struct ComparisonOutput {
  std::string command;               ///< "compare2d", for messages
  std::string title;                 ///< heading of comparison.md
  nlohmann::ordered_json json;       ///< comparison.json: one object per tool (with "ok", "error")
  std::vector<std::string> tools;    ///< e.g. {"febemesh", "gmsh"}
  std::vector<std::string> keys;     ///< rows of comparison.md
  std::vector<HistogramPlot> plots;
  std::string notes;                 ///< markdown appended to comparison.md (e.g. the figures it names)
  std::string unit = "elements";     ///< for the progress lines: "elements", "tets"
  std::string quality_key;           ///< reported in the progress lines, e.g. "min_angle_deg"
  /// Accepted relative difference of the element counts. When json's "element_count_ratio"
  /// (theirs / ours) is outside 1 +- tolerance, comparison.json says so
  /// ("element_count_within_tolerance": false), comparison.md and stderr carry a warning.
  double tolerance = 0.2;
};

/// Writes comparison.json, comparison.md and the plots into `dir` and commits it; unless
/// `quiet`, one line per tool on stderr (count, quality, speed, or its failure). Prints the
/// folder on stdout. Returns exit_ok when every tool meshed, exit_bad_input otherwise.
int finish_comparison(AtomicOutputDir& dir, const ComparisonOutput& out, bool quiet);

}  // namespace febemesh::cli
