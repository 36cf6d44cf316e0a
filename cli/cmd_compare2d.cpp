// febemesh compare2d: our 2D pipeline against Gmsh on the same exact curves (issue 7).

#include <iostream>
#include <sstream>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/command.hpp"
#include "cli/compare_report.hpp"
#include "cli/size_option.hpp"
#include "core/atomic_output.hpp"
#include "core/error.hpp"
#include "core/read_msh.hpp"
#include "dim2/compare_gmsh.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/figures2d.hpp"
#include "dim2/read_domain.hpp"

namespace febemesh::cli {
namespace {

using namespace febemesh::dim2;

/// A mesh of more elements than this is not drawn (as mesh2d --figures auto).
constexpr std::size_t max_drawn_elements = 20000;

const char* const help = R"(usage: febemesh compare2d INPUT -o DIR [options]

Meshes INPUT with febemesh (mesh2d) and with Gmsh (`gmsh -2` on a .geo holding the exact cubic
Bezier pieces of every loop), both with the same element kind, choosing Gmsh's mesh size so that
its element count is within the tolerance of ours, and measures both meshes with the same code.

options:
  -o, --output DIR   output folder (written atomically; an earlier run's folder is
                     replaced, a folder holding other files refused)
  --level N          febemesh's level at the curve (default: the file's levels, else automatic)
  --size H           instead of --level: febemesh's quadrant side at the curve (as mesh2d's)
  --elements KIND    tri (default) | quad | mixed. Gmsh: tri = its default triangles; mixed =
                     Mesh.RecombineAll with Blossom (quad-dominant; it may pair all); quad =
                     the same plus Mesh.SubdivisionAlgorithm 1 (all quads, one split more, as
                     febemesh's quad mode splits its mixed mesh once more)
  --gmsh PROGRAM     the Gmsh program (default: gmsh)
  --tolerance F      accepted relative difference of the element counts (default 0.2)
  --iterations N     at most N Gmsh runs to match the count (default 6)
  --quiet            no progress on stderr

outputs in DIR: mesh.msh (ours), gmsh.geo, gmsh.msh, gmsh.log, comparison.json ({"febemesh": {..},
"gmsh": {..}}: elements, nodes, wall_seconds, elements_per_second, min_angle_deg, max_angle_deg,
area_rel_error, hausdorff_rel, ...), comparison.md, min-angle.svg (0-60 deg for tri, 0-90 for quad/mixed), scaled-jacobian.svg, and
febemesh-mesh.svg and gmsh-mesh.svg: both meshes, each element filled by its smallest corner
angle (up to 20000 elements; comparison.md says when they are not drawn).
Both tools run single-threaded; our wall time is mesh2d + writing mesh.msh, Gmsh's is its whole
run as a subprocess. A tool that fails is reported with "ok": false and its message verbatim.
exit status: 0 both tools meshed, 1 bad input or a tool failed, 2 bad usage.
)";

nlohmann::ordered_json metrics_json(const MeshMetrics2d& m) {
  nlohmann::ordered_json j;
  j["ok"] = m.ok;
  if (!m.ok) j["error"] = m.error;
  j["settings"] = m.settings;
  if (m.ok) {
    j["elements"] = m.elements;
    j["quads"] = m.quads;
    j["nodes"] = m.nodes;
    j["boundary_edges"] = m.boundary_edges;
    j["wall_seconds"] = m.wall_seconds;
    j["elements_per_second"] = m.elements_per_second;
    j["min_angle_deg"] = m.min_angle_deg;
    j["max_angle_deg"] = m.max_angle_deg;
    j["elements_below_30deg"] = m.below_30deg;
    j["min_scaled_jacobian"] = m.min_scaled_jacobian;
    j["mean_scaled_jacobian"] = m.mean_scaled_jacobian;
    j["area_rel_error"] = m.area_rel_error;
    j["hausdorff_rel"] = m.hausdorff_rel;
    j["node_distance_rel"] = m.node_distance_rel;
  }
  return j;
}

int run(const std::vector<std::string>& argv) {
  const Args args(argv, {"--quiet"}, {"-o", "--output", "--level", "--size", "--elements", "--gmsh", "--tolerance", "--iterations"});
  args.expect_positional({"INPUT"});
  const std::string input = args.positional()[0];
  const std::string out = args.value("-o").value_or(args.value_or("--output", ""));
  if (out.empty()) throw UsageError("missing -o DIR");
  check_output_folder(out);  // before the run: never replaces a folder febemesh did not write
  Options2d opt;
  opt.level = args.real_or("--level", no_level, 0, 20);
  const double size = size_option(args);
  opt.elements = element_kind_from(args.choice_or("--elements", "tri", {"tri", "quad", "mixed"}));
  opt.keep_stages = false;
  opt.n_threads = 1;
  CompareOptions2d copt;
  copt.gmsh = args.value_or("--gmsh", "gmsh");
  copt.tolerance = args.real_or("--tolerance", 0.2, 0.01, 1.0);
  copt.max_iterations = args.int_or("--iterations", 6, 1, 20);
  const bool quiet = args.has("--quiet");

  CurveBoundary curve(read_domain(input));
  if (size > 0) {
    const SizedLevel sl = sized_level<2>(curve.bounding_box(), size, 20, input);
    curve.set_root_scale(sl.root_scale);
    opt.level = sl.level;
  }
  if (opt.level != no_level) curve.set_global_level(opt.level);

  AtomicOutputDir dir(out);
  if (!quiet) std::cerr << "compare2d: meshing " << input << " with febemesh and " << copt.gmsh << "\n";
  const Comparison2d c = compare_with_gmsh(curve, opt, copt, dir.path());

  nlohmann::ordered_json j;
  j["input"] = input;
  j["exact_area"] = curve.area();
  j["febemesh"] = metrics_json(c.febemesh);
  j["gmsh"] = metrics_json(c.gmsh);
  j["gmsh"]["mesh_size"] = c.gmsh_size;
  nlohmann::ordered_json trials = nlohmann::ordered_json::array();
  for (const auto& [h, n] : c.gmsh_trials) trials.push_back({{"size", h}, {"elements", n}});
  j["gmsh"]["size_trials"] = trials;
  if (c.febemesh.ok && c.gmsh.ok)
    j["element_count_ratio"] = double(c.gmsh.elements) / double(c.febemesh.elements);
  ComparisonOutput report;
  report.command = "compare2d";
  report.title = "febemesh vs Gmsh (" + std::string(name(opt.elements)) + "): " + input;
  report.json = std::move(j);
  report.tools = {"febemesh", "gmsh"};
  report.keys = {"elements", "quads", "nodes", "boundary_edges", "wall_seconds", "elements_per_second", "min_angle_deg",
                 "max_angle_deg", "elements_below_30deg", "min_scaled_jacobian", "mean_scaled_jacobian",
                 "area_rel_error", "hausdorff_rel", "node_distance_rel"};
  report.quality_key = "min_angle_deg";
  report.tolerance = copt.tolerance;
  // Quads have right angles where triangles have 60 degrees.
  const double best_angle = opt.elements == ElementKind::Tri ? 60.0 : 90.0;
  HistogramPlot angles{"min-angle.svg", "Smallest angle per element", "degrees", 0.0, best_angle, 30, {}};
  HistogramPlot jac{"scaled-jacobian.svg", "Scaled Jacobian per element", "scaled Jacobian", 0.0, 1.0, 25, {}};
  for (const auto& [tool, m] : {std::pair{"febemesh", &c.febemesh}, std::pair{"gmsh", &c.gmsh}}) {
    if (!m->ok) continue;
    angles.series.emplace_back(tool, m->element_min_angle_deg);
    jac.series.emplace_back(tool, m->element_scaled_jacobian);
  }
  report.plots = {std::move(angles), std::move(jac)};
  // Both meshes drawn in the curve's box, each element by its smallest angle (where they can
  // still be read, as mesh2d's figures).
  {
    std::ostringstream md;
    md << "\n## Meshes\n\nEach element filled by its smallest corner angle (blue: the curve):\n\n";
    for (const auto& [tool, file, ok] : {std::tuple{"febemesh", "mesh.msh", c.febemesh.ok},
                                         std::tuple{"gmsh", "gmsh.msh", c.gmsh.ok}}) {
      if (!ok) continue;
      const Mesh<2> mesh = read_msh<2>(dir.file(file));
      const std::string name = std::string(tool) + "-mesh.svg";
      if (mesh.solid.size() <= max_drawn_elements) {
        draw_angle_figure(mesh, curve, dir.file(name), std::string(tool) == "gmsh" ? "Gmsh" : "febemesh");
        md << "- " << tool << ": [" << name << "](" << name << ")\n";
      } else {
        md << "- " << tool << ": " << mesh.solid.size() << " elements, over the " << max_drawn_elements
           << " drawn (an SVG of that many cannot be read), not drawn\n";
      }
    }
    report.notes = md.str();
  }
  return finish_comparison(dir, report, quiet);
}

}  // namespace

FEBEMESH_COMMAND(Command{"compare2d", "compare febemesh with Gmsh on a 2D input (tables and histograms)", help, run});

}  // namespace febemesh::cli
