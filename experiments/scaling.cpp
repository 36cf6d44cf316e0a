// scaling: time and memory against element count, 2D and 3D (issues 7 and 8).
//
// A linear-time mesher spends the same time and memory per element at every size. This runs
// the flange (2D) at levels giving about 10^4 .. 10^6 triangles and the sphere (3D) at levels
// 3 .. 5, each end to end in process (experiments/scaling_runs.hpp: from the parsed input to a
// written mesh.msh, peak RSS growth over the run), and plots microseconds per element and bytes
// per element against the element count on log axes: flat lines are linear growth.
//
// Usage: scaling [--quick] [--max2d N] [--levels3d 3,4,5] [--threads N]
//   --quick: 2D up to 1e5, 3D levels 3,4.
// Output: a table on stdout, results/scaling/scaling.md, scaling.csv, scaling.svg.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include "core/svg_canvas.hpp"
#include "experiments/scaling_runs.hpp"

using namespace febemesh;
using namespace febemesh::bench;

namespace {

struct Point2 {
  std::string series;
  double elements, us_per_element, bytes_per_element;
};

/// Log-log plot of y(x) per series, with decade grid lines.
void plot(const std::vector<Point2>& pts, bool memory, const std::string& title, const fs::path& file) {
  SvgCanvas c(640.0, 30.0);
  auto y_of = [&](const Point2& p) { return memory ? p.bytes_per_element : p.us_per_element; };
  // Log axes: a point without a positive value (a failed memory measurement) cannot be drawn,
  // and one would make the decade loops below start at -infinity (they never ended and took
  // the whole memory of the machine).
  std::vector<Point2> drawn;
  for (const auto& p : pts)
    if (p.elements > 0 && y_of(p) > 0 && std::isfinite(y_of(p))) drawn.push_back(p);
  if (drawn.empty()) return;
  double x0 = 1e300, x1 = 0, y0 = 1e300, y1 = 0;
  for (const auto& p : drawn) {
    x0 = std::min(x0, p.elements), x1 = std::max(x1, p.elements);
    y0 = std::min(y0, y_of(p)), y1 = std::max(y1, y_of(p));
  }
  const double lx0 = std::floor(std::log10(x0)), lx1 = std::ceil(std::log10(x1));
  const double ly0 = std::floor(std::log10(y0)), ly1 = std::ceil(std::log10(y1));
  // Plot box: x in [0, 10], y in [0, 6] (mesh units), decades spread over it.
  auto X = [&](double x) { return 10.0 * (std::log10(x) - lx0) / std::max(1.0, lx1 - lx0); };
  auto Y = [&](double y) { return 6.0 * (std::log10(y) - ly0) / std::max(1.0, ly1 - ly0); };
  c.set_view(Box<2>{Point<2>(-1.6, -1.0), Point<2>(12.5, 7.0)});
  for (double d = lx0; d <= lx1; ++d) {
    c.line(Point<2>(X(std::pow(10, d)), 0), Point<2>(X(std::pow(10, d)), 6), {"none", "#dddddd", 0.8, 1.0});
    c.text(Point<2>(X(std::pow(10, d)) - 0.2, -0.45), "1e" + std::to_string(int(d)), 11.0, "#444444");
  }
  for (double d = ly0; d <= ly1; ++d) {
    c.line(Point<2>(0, Y(std::pow(10, d))), Point<2>(10, Y(std::pow(10, d))), {"none", "#dddddd", 0.8, 1.0});
    c.text(Point<2>(-1.5, Y(std::pow(10, d)) - 0.1), "1e" + std::to_string(int(d)), 11.0, "#444444");
  }
  c.polygon({Point<2>(0, 0), Point<2>(10, 0), Point<2>(10, 6), Point<2>(0, 6)}, {"none", "#444444", 1.0, 1.0});
  std::vector<std::string> series;
  for (const auto& p : drawn)
    if (std::find(series.begin(), series.end(), p.series) == series.end()) series.push_back(p.series);
  for (std::size_t s = 0; s < series.size(); ++s) {
    std::vector<Point<2>> line;
    for (const auto& p : drawn)
      if (p.series == series[s]) line.emplace_back(X(p.elements), Y(y_of(p)));
    const std::string colour = svg_palette(int(s));
    c.polyline(line, {"none", colour, 2.0, 1.0});
    for (const auto& q : line) c.dot(q, 3.5, {colour, "none", 0.0, 1.0});
    c.text(Point<2>(10.3, 5.6 - 0.5 * double(s)), series[s], 12.0, colour);
  }
  c.text(Point<2>(0, 6.4), title, 14.0, "#222222");
  c.text(Point<2>(4.0, -0.9), "elements (log)", 12.0, "#222222");
  c.write(file);
}

}  // namespace

int main(int argc, char** argv) {
  double max2d = 1.2e6;
  std::vector<int> levels3d{3, 4, 5};
  int threads = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      max2d = 1.2e5;
      levels3d = {3, 4};
    } else if (a == "--max2d" && i + 1 < argc) {
      max2d = std::stod(argv[++i]);
    } else if (a == "--levels3d" && i + 1 < argc) {
      levels3d.clear();
      std::stringstream ss(argv[++i]);
      for (std::string s; std::getline(ss, s, ',');) levels3d.push_back(std::stoi(s));
    } else if (a == "--threads" && i + 1 < argc) {
      threads = std::stoi(argv[++i]);
    } else {
      std::cerr << "usage: scaling [--quick] [--max2d N] [--levels3d 3,4,5] [--threads N]\n";
      return 2;
    }
  }
  const std::string src = FEBEMESH_SOURCE_DIR, data = FEBEMESH_DATA_DIR;
  const fs::path out = fs::path(src) / "results" / "scaling";
  fs::create_directories(out);
  std::vector<Point2> pts;
  std::ostringstream table;
  table << "| run | elements | wall s | cpu s | us/element (cpu) | peak MB | B/element |\n|---|---|---|---|---|---|---|\n";
  auto record = [&](const std::string& series, const std::string& tag, const OurRun& r) {
    if (!r.ok) {
      std::cout << tag << ": failed: " << r.error.substr(0, 300) << "\n";
      table << "| " << tag << " | failed: " << r.error.substr(0, 120) << " | | | | | |\n";
      return;
    }
    // CPU time per element: the shared machine stretches wall time, not CPU time.
    const double us = 1e6 * r.cpu_seconds / double(r.elements);
    pts.push_back({series, double(r.elements), us, r.bytes_per_element()});
    std::ostringstream row;
    row << "| " << tag << " | " << r.elements << " | " << fixed(r.wall_seconds) << " | " << fixed(r.cpu_seconds)
        << " | " << fixed(us, 2) << " | " << fixed(r.peak_bytes / 1e6, 1) << " | " << fixed(r.bytes_per_element(), 0)
        << " |";
    table << row.str() << "\n";
    std::cout << row.str() << "\n" << std::flush;
  };

  // 2D: the flange; its element count roughly doubles per level (graded away from the curve).
  const dim2::CurveBoundary flange(dim2::read_domain(src + "/examples/flange.json"));
  for (double level = 6.0;; level += 1.0) {
    const OurRun r = run_ours_2d(flange, level, threads, out / "flange");
    record("2D flange", "flange L" + fixed(level, 0), r);
    if (!r.ok || 2.2 * double(r.elements) > max2d) break;
  }
  // 3D: the sphere.
  for (const int level : levels3d) {
    const OurRun r = run_ours_3d(data + "/3d/sphere966.off", level, threads, out / "sphere966");
    record("3D sphere966", "sphere966 L" + std::to_string(level), r);
  }

  plot(pts, false, "CPU microseconds per element (flat = linear time)", out / "scaling-time.svg");
  plot(pts, true, "peak bytes per element (flat = linear memory)", out / "scaling-memory.svg");
  {
    std::ofstream csv(out / "scaling.csv");
    csv << "series,elements,us_per_element_cpu,bytes_per_element\n";
    for (const auto& p : pts) csv << p.series << "," << p.elements << "," << p.us_per_element << "," << p.bytes_per_element << "\n";
  }
  std::ofstream(out / "scaling.md") << "# Scaling: time and memory against element count\n\n"
                                    << "End to end in process (parsed input to written mesh.msh), " << threads
                                    << " thread(s). Plots: [time](scaling-time.svg), [memory](scaling-memory.svg); "
                                       "data: [scaling.csv](scaling.csv).\n\n"
                                    << table.str();
  std::cout << "wrote " << (out / "scaling.md").string() << "\n";
  return 0;
}
