// Experiment: what does the thin-boundary-quadrant rule buy? (issue 7, `buffer_study`)
//
// The paper builds a boundary quadrant between every free edge Q1 Q2 of the interior quadrants
// and the curve. When an interior quadrant almost touches the curve, the projections P1, P2 are
// very close to Q1, Q2 and the boundary quadrant is a sliver, whatever the smoothing does. The
// paper is silent on this; febemesh drops interior quadrants nearer to the curve than a fraction
// of their size (Options2d::buffer, `mesh2d --buffer F`, default 0.35), so that the boundary
// quadrant takes their place and is thicker.
//
// We mesh every bundled example and every glyph of ../shared/data/2d at two levels with the
// buffer fraction F = 0, 0.05, ..., 0.5, triangles, and measure:
//   - the boundary quadrants' thinness before smoothing: min over four-sided boundary quadrants
//     of min(|Q1 P1|, |Q2 P2|) / |Q1 Q2| (what the rule acts on);
//   - the FE mesh: smallest angle, mean and 5th percentile of the per-element smallest angle,
//     the smallest angle among elements of boundary quadrants, element count, validity;
// once with the paper's pipeline alone (4 Laplacian passes, no quality pass: improve_rounds = 0)
// and once with febemesh's default quality pass (edge flips and angle-guarded smoothing), which
// can hide what the rule does.
//
// Output: results/buffer_study/buffer_study.md (summary per fraction and the per-run table),
// buffer_study.csv, buffer_study.svg. Usage: buffer_study [OUTDIR] [--quick]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/quality.hpp"
#include "core/svg_canvas.hpp"
#include "core/validate.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"

using namespace febemesh;
using namespace febemesh::dim2;
namespace fs = std::filesystem;

namespace {

/// One mesh2d run and what we measured on it.
struct Run {
  std::string input;
  int level = 0;
  bool quality_pass = false;
  double fraction = 0.0;
  bool ok = false;
  std::string error;
  bool valid = false;
  std::size_t elements = 0;
  std::size_t dropped = 0;          ///< interior quadrants dropped by the rule
  int repairs = 0;                  ///< local refinements the construction asked for
  double thinnest = 0.0;            ///< min (|Q1P1|, |Q2P2|) / |Q1Q2| over boundary quadrants
  std::size_t n_thin = 0;           ///< boundary quadrants with that ratio below 0.1
  double min_angle = 0.0, mean_angle = 0.0, p5_angle = 0.0, boundary_min_angle = 0.0;
};

/// Thinness of the boundary quadrants before smoothing (after corner pulling).
void measure_thinness(const QuadrantComplex& qc, Run& run) {
  run.thinnest = 1e300;
  for (const BoundaryQuadrant& b : qc.boundary) {
    if (b.is_triangle()) continue;
    const P2 q2 = qc.points[std::size_t(b.node[0])], q1 = qc.points[std::size_t(b.node[1])];
    const P2 p1 = qc.points[std::size_t(b.node[2])], p2 = qc.points[std::size_t(b.node[3])];
    const double r = std::min((p1 - q1).norm(), (p2 - q2).norm()) / (q2 - q1).norm();
    run.thinnest = std::min(run.thinnest, r);
    run.n_thin += r < 0.1;
  }
  if (run.thinnest > 1e299) run.thinnest = 0.0;  // no four-sided boundary quadrant at all
}

void measure_angles(const Mesh<2>& m, Run& run) {
  std::vector<double> per_element;
  run.boundary_min_angle = 180.0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const auto pts = element_points<2>(m.solid, ElemId{std::int32_t(e)}, m.points);
    const double a = element_quality<2>(m.solid.type[e], pts.span()).min_angle_deg;
    per_element.push_back(a);
    if (m.from_boundary_cell[e]) run.boundary_min_angle = std::min(run.boundary_min_angle, a);
  }
  std::sort(per_element.begin(), per_element.end());
  run.elements = per_element.size();
  run.min_angle = per_element.front();
  double sum = 0.0;
  for (double a : per_element) sum += a;
  run.mean_angle = sum / double(per_element.size());
  run.p5_angle = per_element[std::size_t(0.05 * double(per_element.size() - 1))];
}

Run mesh_once(const std::string& input, int level, bool quality_pass, double fraction) {
  Run run;
  run.input = fs::path(input).stem().string();
  run.level = level;
  run.quality_pass = quality_pass;
  run.fraction = fraction;
  try {
    CurveBoundary curve(read_domain(input));
    curve.set_global_level(level);
    Options2d opt;
    opt.level = level;
    opt.buffer = fraction;
    opt.improve_rounds = quality_pass ? Options2d{}.improve_rounds : 0;
    opt.n_threads = 1;
    opt.keep_stages = true;  // for the boundary quadrants before smoothing (Result2d::complex)
    const Result2d r = mesh2d(curve, opt);
    run.dropped = r.n_buffer_dropped;
    run.repairs = r.n_repairs;
    measure_thinness(r.complex, run);
    measure_angles(r.fe.mesh, run);
    ValidateOptions<2> vo;
    vo.expected_euler = curve.n_components() - curve.n_holes();
    vo.boundary_distance = [&](const P2& p) { return curve.closest_point(p).distance; };
    const Box<2> bb = curve.bounding_box();
    vo.boundary_tolerance = 1e-10 * (bb.hi - bb.lo).norm();
    run.valid = validate<2>(r.fe.mesh, vo).valid;
    run.ok = true;
  } catch (const std::exception& e) {
    run.error = e.what();
    const auto nl = run.error.find('\n');
    if (nl != std::string::npos) run.error.resize(nl);
  }
  return run;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// Per (quality pass, fraction): averages over the runs that meshed.
struct Summary {
  std::size_t runs = 0, ok = 0, valid = 0, thin = 0;
  double min_angle = 1e9, mean_min_angle = 0, mean_angle = 0, p5 = 0, boundary_min = 0, elements_ratio = 0;
  double thinnest = 1e9;
};

/// Plot: mean over runs of the smallest angle, 5th percentile and boundary-quadrant smallest
/// angle against F (top), and the element count relative to F = 0 (bottom), both variants.
void plot(const std::map<std::pair<bool, double>, Summary>& sums, const fs::path& file) {
  SvgCanvas svg(900.0, 40.0);
  svg.set_view(Box<2>{P2(-0.18, -1.25), P2(1.75, 1.12)});
  const SvgStyle axis{"none", "black", 1.0, 1.0};
  // Top panel: angles in [0, 45] -> y in [0, 1]; bottom: ratio in [0.8, 1.2] -> y in [-1.1, -0.3].
  auto top = [](double f, double deg) { return P2(f * 2.0, deg / 45.0); };
  double rmax = 1.2;
  for (const auto& [key, s] : sums) rmax = std::max(rmax, s.elements_ratio);
  rmax = std::ceil(rmax * 5.0) / 5.0;
  auto bottom = [rmax](double f, double ratio) { return P2(f * 2.0, -1.1 + (ratio - 0.8) / (rmax - 0.8) * 0.8); };
  svg.line(P2(0, 0), P2(1.0, 0), axis);
  svg.line(P2(0, 0), P2(0, 1.0), axis);
  svg.line(P2(0, -1.1), P2(1.0, -1.1), axis);
  svg.line(P2(0, -1.1), P2(0, -0.3), axis);
  for (int t = 0; t <= 5; ++t) {
    const double f = 0.1 * t;
    svg.text(P2(f * 2.0 - 0.02, -0.06), fmt("%.1f", f), 11.0);
    svg.text(P2(f * 2.0 - 0.02, -1.16), fmt("%.1f", f), 11.0);
  }
  for (int d = 0; d <= 45; d += 15) {
    svg.line(top(0, d), top(-0.01, d), axis);
    svg.text(top(-0.07, d) + P2(0, -0.01), std::to_string(d), 11.0);
  }
  for (double q : {0.8, 1.0, rmax}) svg.text(bottom(-0.09, q) + P2(0, -0.01), fmt("%.1f", q), 11.0);
  svg.line(bottom(0, 1.0), bottom(0.5, 1.0), SvgStyle{"none", "#bbbbbb", 0.8, 1.0});
  svg.line(top(0.35, 0), top(0.35, 45), SvgStyle{"none", "#bbbbbb", 0.8, 1.0});
  svg.text(top(0.355, 43), "default 0.35", 11.0, "#777777");
  int colour = 0;
  for (bool qp : {false, true}) {
    struct Curve {
      std::string label;
      double Summary::*field;
      double width;
    };
    const std::vector<Curve> curves{{"mean smallest angle", &Summary::mean_min_angle, 2.2},
                                    {"mean 5th percentile", &Summary::p5, 1.2},
                                    {"mean smallest angle in boundary quadrants", &Summary::boundary_min, 0.7}};
    const std::string c = svg_palette(qp ? 2 : 0);
    int k = 0;
    for (const Curve& cv : curves) {
      std::vector<P2> pts;
      for (const auto& [key, s] : sums)
        if (key.first == qp) pts.push_back(top(key.second, s.*cv.field));
      svg.polyline(pts, SvgStyle{"none", c, cv.width, 1.0});
      for (const P2& p : pts) svg.dot(p, cv.width + 1.0, SvgStyle{c, "none", 0.0, 1.0});
      svg.text(P2(1.05, 1.0 - 0.07 * (colour * 4 + k)), (qp ? "quality pass: " : "paper only: ") + cv.label, 11.0, c);
      ++k;
    }
    std::vector<P2> pts;
    for (const auto& [key, s] : sums)
      if (key.first == qp) pts.push_back(bottom(key.second, s.elements_ratio));
    svg.polyline(pts, SvgStyle{"none", c, 2.0, 1.0});
    for (const P2& p : pts) svg.dot(p, 3.0, SvgStyle{c, "none", 0.0, 1.0});
    svg.text(P2(1.05, -0.35 - 0.07 * colour), (qp ? "quality pass" : "paper only"), 11.0, c);
    ++colour;
  }
  svg.text(P2(0.0, 1.06), "Smallest angles (degrees) against the buffer fraction F", 14.0);
  svg.text(P2(0.0, -0.24), "Element count relative to F = 0", 14.0);
  svg.text(P2(0.75, -1.23), "buffer fraction F (means over the inputs and levels meshed at every F)", 12.0);
  svg.write(file);
}

}  // namespace

int main(int argc, char** argv) {
  fs::path out = fs::path(FEBEMESH_SOURCE_DIR) / "results/buffer_study";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else
      out = a;
  }
  fs::create_directories(out);

  // The inputs: the bundled examples (file units: cm) and the glyphs (font units), at the level
  // their comparison runs use (6) and one finer; --quick: the examples at one level.
  std::vector<std::string> inputs;
  for (const auto& e : fs::directory_iterator(fs::path(FEBEMESH_SOURCE_DIR) / "examples"))
    if (e.path().extension() == ".json") inputs.push_back(e.path().string());
  if (!quick)
    for (const auto& e : fs::directory_iterator(fs::path(FEBEMESH_DATA_DIR) / "2d"))
      if (e.path().extension() == ".svg") inputs.push_back(e.path().string());
  std::sort(inputs.begin(), inputs.end());
  const std::vector<int> levels = quick ? std::vector<int>{5} : std::vector<int>{5, 6};
  std::vector<double> fractions;
  for (int k = 0; k <= 10; ++k) fractions.push_back(0.05 * k);
  std::cout << "Buffer study: " << inputs.size() << " inputs x " << levels.size() << " levels x " << fractions.size()
            << " fractions x 2 variants\n";

  std::vector<Run> runs;
  for (const std::string& input : inputs)
    for (int level : levels)
      for (bool qp : {false, true})
        for (double f : fractions) {
          runs.push_back(mesh_once(input, level, qp, f));
          const Run& r = runs.back();
          if (r.ok)
            std::printf("%-26s L%d %-7s F=%.2f  %6zu el  %2d repairs  min %5.1f  p5 %5.1f  bq-min %5.1f  thinnest %.3f  %s\n",
                        r.input.c_str(), level, qp ? "quality" : "paper", f, r.elements, r.repairs, r.min_angle, r.p5_angle,
                        r.boundary_min_angle, r.thinnest, r.valid ? "valid" : "INVALID");
          else
            std::printf("%-26s L%d %-7s F=%.2f  FAILED: %s\n", r.input.c_str(), level, qp ? "quality" : "paper", f,
                        r.error.c_str());
        }

  // Element count relative to F = 0 of the same input, level and variant.
  std::map<std::tuple<std::string, int, bool>, std::size_t> base;
  for (const Run& r : runs)
    if (r.ok && r.fraction == 0.0) base[{r.input, r.level, r.quality_pass}] = r.elements;
  // Averages compare like with like: only inputs and levels that meshed at every fraction in
  // both variants enter them (a run that fails at large F would otherwise leave the average).
  std::map<std::pair<std::string, int>, bool> complete;
  for (const Run& r : runs) {
    auto it = complete.emplace(std::pair{r.input, r.level}, true).first;
    it->second = it->second && r.ok;
  }
  std::size_t n_complete = 0;
  for (const auto& [key, ok] : complete) n_complete += ok;
  std::map<std::pair<bool, double>, Summary> sums;
  for (const Run& r : runs) {
    Summary& s = sums[{r.quality_pass, r.fraction}];
    ++s.runs;
    if (!r.ok) continue;
    ++s.ok;
    s.valid += r.valid;
    if (!complete[{r.input, r.level}]) continue;
    s.thin += r.n_thin;
    s.min_angle = std::min(s.min_angle, r.min_angle);
    s.thinnest = std::min(s.thinnest, r.thinnest);
    s.mean_min_angle += r.min_angle;
    s.mean_angle += r.mean_angle;
    s.p5 += r.p5_angle;
    s.boundary_min += r.boundary_min_angle;
    const auto b = base.find({r.input, r.level, r.quality_pass});
    s.elements_ratio += b != base.end() ? double(r.elements) / double(b->second) : 1.0;
  }
  for (auto& [key, s] : sums) {
    if (n_complete == 0) continue;
    for (double* v : {&s.mean_min_angle, &s.mean_angle, &s.p5, &s.boundary_min, &s.elements_ratio})
      *v /= double(n_complete);
  }

  std::ostringstream md, csv;
  md << "# Buffer study: the thin-boundary-quadrant rule\n\n"
     << "Interior quadrants nearer the curve than F x their size are dropped (`mesh2d --buffer F`, default 0.35). "
     << inputs.size() << " inputs (bundled examples and glyphs) at levels";
  for (int l : levels) md << " " << l;
  md << ", triangles. *Paper only*: 4 Laplacian passes and nothing else; *quality pass*: febemesh's default edge "
        "flips and angle-guarded smoothing after it. Angles are each element's smallest angle; *thinnest* is the "
        "smallest min(|Q1P1|, |Q2P2|) / |Q1Q2| over boundary quadrants before smoothing; *thin* counts boundary "
        "quadrants with that ratio below 0.1. *meshed* and *valid* count every run; the other columns "
        "(and the plot) are over the "
     << n_complete << " of " << complete.size()
     << " input-level pairs that meshed at every F in both variants, so each F averages the same meshes.\n\n"
     << "![plot](buffer_study.svg)\n\n"
     << "| variant | F | meshed | valid | min angle | mean of min angle | mean angle | mean 5th pct | mean bq min "
        "angle | thinnest | thin bq | elements / elements(F=0) |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& [key, s] : sums) {
    md << "| " << (key.first ? "quality pass" : "paper only") << " | " << fmt("%.2f", key.second) << " | " << s.ok
       << "/" << s.runs << " | " << s.valid << " | ";
    if (s.ok == 0) {
      md << "- | - | - | - | - | - | - | - |\n";
      continue;
    }
    md << fmt("%.1f", s.min_angle) << " | " << fmt("%.1f", s.mean_min_angle) << " | " << fmt("%.1f", s.mean_angle)
       << " | " << fmt("%.1f", s.p5) << " | " << fmt("%.1f", s.boundary_min) << " | " << fmt("%.3f", s.thinnest)
       << " | " << s.thin << " | " << fmt("%.3f", s.elements_ratio) << " |\n";
  }
  md << "\n## Every run\n\n| input | level | variant | F | elements | dropped | repairs | min angle | mean | 5th pct | bq min "
        "| thinnest | valid |\n|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  csv << "input,level,variant,fraction,ok,valid,elements,dropped,repairs,min_angle,mean_angle,p5_angle,boundary_min_angle,"
         "thinnest,thin,error\n";
  for (const Run& r : runs) {
    const std::string variant = r.quality_pass ? "quality" : "paper";
    md << "| " << r.input << " | " << r.level << " | " << variant << " | " << fmt("%.2f", r.fraction) << " | ";
    if (!r.ok) {
      md << "failed: " << r.error << " | | | | | | | | |\n";
    } else {
      md << r.elements << " | " << r.dropped << " | " << r.repairs << " | " << fmt("%.1f", r.min_angle) << " | " << fmt("%.1f", r.mean_angle)
         << " | " << fmt("%.1f", r.p5_angle) << " | " << fmt("%.1f", r.boundary_min_angle) << " | "
         << fmt("%.3f", r.thinnest) << " | " << (r.valid ? "yes" : "**no**") << " |\n";
    }
    std::string err = r.error;
    std::replace(err.begin(), err.end(), ',', ';');
    csv << r.input << "," << r.level << "," << variant << "," << r.fraction << "," << r.ok << "," << r.valid << ","
        << r.elements << "," << r.dropped << "," << r.repairs << "," << r.min_angle << "," << r.mean_angle << "," << r.p5_angle << ","
        << r.boundary_min_angle << "," << r.thinnest << "," << r.n_thin << ",\"" << err << "\"\n";
  }
  std::ofstream(out / "buffer_study.md") << md.str();
  std::ofstream(out / "buffer_study.csv") << csv.str();
  plot(sums, out / "buffer_study.svg");
  std::cout << "wrote " << (out / "buffer_study.md").string() << ", buffer_study.csv, buffer_study.svg\n";
  std::size_t failed = 0;
  for (const Run& r : runs) failed += !r.ok;
  return failed == runs.size() ? 1 : 0;
}
