#include "cli/compare_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <iostream>

#include "cli/command.hpp"
#include "core/error.hpp"
#include "core/svg_canvas.hpp"

namespace febemesh::cli {

void write_histogram_svg(const std::filesystem::path& path, const std::string& title, const std::string& x_label,
                         double lo, double hi, int n_bins, const Series& series) {
  std::vector<std::vector<double>> frac(series.size(), std::vector<double>(std::size_t(n_bins), 0.0));
  double top = 0.0;
  for (std::size_t s = 0; s < series.size(); ++s) {
    const auto& v = series[s].second;
    for (double x : v) {
      const int b = std::clamp(static_cast<int>(std::floor((x - lo) / (hi - lo) * n_bins)), 0, n_bins - 1);
      frac[s][std::size_t(b)] += 1.0;
    }
    for (double& f : frac[s]) {
      f = v.empty() ? 0.0 : f / double(v.size());
      top = std::max(top, f);
    }
  }
  if (top <= 0) top = 1.0;
  // Plot frame in figure units: x in [0, 1.6], bar height in [0, 1].
  const double width = 1.6, bin_w = width / n_bins, bar_w = bin_w / double(std::max<std::size_t>(1, series.size()));
  SvgCanvas svg(720.0, 40.0);
  svg.set_view(Box<2>{Point<2>(-0.12, -0.16), Point<2>(width + 0.05, 1.12)});
  const SvgStyle axis{"none", "black", 1.0, 1.0};
  svg.line(Point<2>(0, 0), Point<2>(width, 0), axis);
  svg.line(Point<2>(0, 0), Point<2>(0, 1.0), axis);
  for (std::size_t s = 0; s < series.size(); ++s) {
    const SvgStyle bar{svg_palette(int(s)), "none", 0.0, 0.85};
    for (int b = 0; b < n_bins; ++b) {
      const double h = frac[s][std::size_t(b)] / top;
      if (h <= 0) continue;
      const double x0 = b * bin_w + double(s) * bar_w;
      svg.polygon({Point<2>(x0, 0), Point<2>(x0 + bar_w, 0), Point<2>(x0 + bar_w, h), Point<2>(x0, h)}, bar);
    }
    svg.polygon({Point<2>(1.05, 1.02 - 0.06 * double(s)), Point<2>(1.09, 1.02 - 0.06 * double(s)),
                 Point<2>(1.09, 1.06 - 0.06 * double(s)), Point<2>(1.05, 1.06 - 0.06 * double(s))},
                bar);
    svg.text(Point<2>(1.11, 1.02 - 0.06 * double(s)),
             series[s].first + " (" + std::to_string(series[s].second.size()) + ")", 13.0);
  }
  char buf[64];
  for (int t = 0; t <= 4; ++t) {
    const double x = width * t / 4.0;
    svg.line(Point<2>(x, 0), Point<2>(x, -0.02), axis);
    std::snprintf(buf, sizeof buf, "%g", lo + (hi - lo) * t / 4.0);
    svg.text(Point<2>(x - 0.02, -0.07), buf, 12.0);
  }
  std::snprintf(buf, sizeof buf, "%.3g", top);
  svg.text(Point<2>(-0.11, 0.98), buf, 12.0);
  svg.text(Point<2>(-0.11, 0.50), "fraction", 12.0);
  svg.text(Point<2>(0.6, -0.14), x_label, 13.0);
  svg.text(Point<2>(0.0, 1.07), title, 15.0);
  svg.write(path);
}

namespace {

std::string cell(const nlohmann::ordered_json& v) {
  if (v.is_null()) return "-";
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
    return buf;
  }
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

}  // namespace

std::string comparison_markdown(const std::string& title, const nlohmann::ordered_json& comparison,
                                const std::vector<std::string>& tools, const std::vector<std::string>& keys) {
  std::ostringstream os;
  os << "# " << title << "\n\n| metric |";
  for (const auto& t : tools) os << " " << t << " |";
  os << "\n|---|";
  for (std::size_t i = 0; i < tools.size(); ++i) os << "---:|";
  os << "\n";
  for (const auto& k : keys) {
    os << "| " << k << " |";
    for (const auto& t : tools) {
      const auto& obj = comparison.at(t);
      os << " " << (obj.contains(k) ? cell(obj.at(k)) : std::string("-")) << " |";
    }
    os << "\n";
  }
  os << "\n";
  for (const auto& t : tools) {
    const auto& obj = comparison.at(t);
    if (obj.contains("settings")) os << "- **" << t << "**: " << obj.at("settings").get<std::string>() << "\n";
  }
  for (const auto& t : tools) {
    const auto& obj = comparison.at(t);
    if (obj.value("ok", true)) continue;
    os << "\n**" << t << " failed:**\n\n```\n" << obj.value("error", std::string()) << "\n```\n";
  }
  return os.str();
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream os(path);
  os << text;
  if (!os) throw InputError(path.string() + ": cannot write");
}

int finish_comparison(AtomicOutputDir& dir, const ComparisonOutput& out, bool quiet) {
  nlohmann::ordered_json json = out.json;
  std::string md = comparison_markdown(out.title, json, out.tools, out.keys);
  if (json.contains("element_count_ratio")) {
    const double ratio = json["element_count_ratio"].get<double>();
    const bool within = std::abs(ratio - 1.0) <= out.tolerance;
    json["element_count_within_tolerance"] = within;
    if (!within) {
      std::ostringstream w;
      w << out.tools.at(1) << "'s element count is " << ratio << " x ours, outside the tolerance of "
        << out.tolerance << " (its trials are in comparison.json): the rates and qualities compare meshes of "
        << "different sizes";
      md += "\n**Warning:** " + w.str() + ".\n";
      if (!quiet) std::cerr << out.command << ": warning: " << w.str() << "\n";
    }
  }
  md += out.notes;
  write_text(dir.file("comparison.json"), json.dump(2) + "\n");
  write_text(dir.file("comparison.md"), md);
  for (const HistogramPlot& p : out.plots)
    write_histogram_svg(dir.file(p.file), p.title, p.x_label, p.lo, p.hi, p.n_bins, p.series);
  dir.commit();
  bool all_ok = true;
  for (const std::string& tool : out.tools) {
    const auto& t = json.at(tool);
    const bool ok = t.value("ok", false);
    all_ok = all_ok && ok;
    if (quiet) continue;
    if (ok)
      std::cerr << out.command << ": " << tool << ": " << t.value("elements", std::size_t(0)) << " " << out.unit << ", "
                << out.quality_key << " " << t.value(out.quality_key, 0.0) << ", "
                << t.value("elements_per_second", 0.0) << " " << out.unit << "/s\n";
    else
      std::cerr << out.command << ": " << tool << " failed: " << t.value("error", std::string()) << "\n";
  }
  std::cout << dir.final_path().string() << "\n";
  return all_ok ? exit_ok : exit_bad_input;
}

}  // namespace febemesh::cli
