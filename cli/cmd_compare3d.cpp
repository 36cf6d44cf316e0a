// febemesh compare3d: our octree pipeline against TetGen on the same closed surface (issue 7).

#include <iostream>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/command.hpp"
#include "cli/compare_report.hpp"
#include "cli/size_option.hpp"
#include "core/atomic_output.hpp"
#include "core/error.hpp"
#include "core/read_msh.hpp"
#include "dim3/compare_tetgen.hpp"
#include "dim3/figures3d.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::cli {
namespace {

using namespace febemesh::dim3;

/// A section figure of more polygons than this is not drawn (as mesh3d --figures auto).
constexpr std::size_t max_section_polygons = 60000;

const char* const help = R"(usage: febemesh compare3d SURFACE -o DIR [options]

Meshes the solid bounded by SURFACE (OFF, STL, OBJ, PLY) with febemesh (mesh3d) and with TetGen
(libtet in process, switches pq1.414/10a<vol>Q), choosing TetGen's volume bound so that its tet
count is within the tolerance of ours, and measures both meshes with the same code.

options:
  -o, --output DIR   output folder (written atomically; an earlier run's folder is
                     replaced, a folder holding other files refused)
  --level N          febemesh's octree level at the surface (1..9, default 4)
  --size H           instead of --level: febemesh's octant side at the surface (as mesh3d's)
  --extra-levels N   curvature and feature levels above it (0..4, default 2)
  --target-dihedral DEG  febemesh's optimisation aim (0..35, default 30; as mesh3d's)
  --tolerance F      accepted relative difference of the tet counts (default 0.2)
  --iterations N     at most N TetGen runs to match the count (default 6)
  --quiet            no progress on stderr

outputs in DIR: mesh.msh (ours, if it meshed), tetgen.msh, tetgen.log, comparison.json ({"febemesh": {..},
"tetgen": {..}}: elements, nodes, wall_seconds, elements_per_second, peak_memory_bytes,
min_dihedral_deg, max_dihedral_deg, slivers_below_10deg, volume_rel_error, hausdorff_rel, ...),
comparison.md, min-dihedral.svg, max-dihedral.svg, radius-ratio.svg, scaled-jacobian.svg, and
febemesh-section-x.svg (-y, -z) and tetgen-section-x.svg (-y, -z): both meshes cut by the same
three planes (mesh3d's figures), each cut tetrahedron coloured by its smallest dihedral angle
(a cut of more than 60000 polygons is left out; comparison.md says so).
Each tool runs single-threaded in a forked child, timed from reading the file to writing its
.msh; peak_memory_bytes is the child's peak resident memory growth. A tool that fails is
reported with "ok": false and its message verbatim (libtet 1.5 can crash while failing: then
what TetGen printed, kept in tetgen.log). When TetGen's count cannot be brought within the
tolerance (e.g. the input's triangles alone need more tets), comparison.md warns.
exit status: 0 both tools meshed, 1 bad input or a tool failed, 2 bad usage.
)";

nlohmann::ordered_json metrics_json(const MeshMetrics3d& m) {
  nlohmann::ordered_json j;
  j["ok"] = m.ok;
  if (!m.ok) j["error"] = m.error;
  j["settings"] = m.settings;
  if (m.ok) {
    j["elements"] = m.elements;
    j["nodes"] = m.nodes;
    j["boundary_triangles"] = m.boundary_triangles;
    j["wall_seconds"] = m.wall_seconds;
    j["elements_per_second"] = m.elements_per_second;
    j["peak_memory_bytes"] = m.peak_memory_bytes;
    j["min_dihedral_deg"] = m.min_dihedral_deg;
    j["max_dihedral_deg"] = m.max_dihedral_deg;
    j["slivers_below_10deg"] = m.slivers_below_10deg;
    j["min_scaled_jacobian"] = m.min_scaled_jacobian;
    j["mean_scaled_jacobian"] = m.mean_scaled_jacobian;
    j["max_radius_ratio"] = m.max_radius_ratio;
    j["volume_rel_error"] = m.volume_rel_error;
    j["hausdorff_rel"] = m.hausdorff_rel;
  }
  return j;
}

int run(const std::vector<std::string>& argv) {
  const Args args(argv, {"--quiet"}, {"-o", "--output", "--level", "--size", "--extra-levels", "--target-dihedral", "--tolerance", "--iterations"});
  args.expect_positional({"SURFACE"});
  const std::string input = args.positional()[0];
  const std::string out = args.value("-o").value_or(args.value_or("--output", ""));
  if (out.empty()) throw UsageError("missing -o DIR");
  Options3d opt;
  opt.level = args.int_or("--level", 4, 1, 9);
  opt.size = size_option(args);
  opt.extra_levels = args.int_or("--extra-levels", 2, 0, 4);
  opt.n_threads = 1;
  set_target_dihedral(opt, args.real_or("--target-dihedral", opt.target_dihedral_deg, 0.0, 35.0));
  CompareOptions3d copt;
  copt.tolerance = args.real_or("--tolerance", 0.2, 0.01, 1.0);
  copt.max_iterations = args.int_or("--iterations", 6, 1, 20);
  const bool quiet = args.has("--quiet");

  AtomicOutputDir dir(out);
  if (!quiet) std::cerr << "compare3d: meshing " << input << " with febemesh and TetGen\n";
  const Comparison3d c = compare_with_tetgen(input, opt, copt, dir.path());

  nlohmann::ordered_json j;
  j["input"] = input;
  j["febemesh"] = metrics_json(c.febemesh);
  j["febemesh"]["target_dihedral_deg"] = opt.target_dihedral_deg;
  if (opt.size > 0) j["febemesh"]["size"] = opt.size;
  j["tetgen"] = metrics_json(c.tetgen);
  j["tetgen"]["switches"] = c.tetgen_switches;
  nlohmann::ordered_json trials = nlohmann::ordered_json::array();
  for (const auto& [v, n] : c.tetgen_trials) trials.push_back({{"volume_bound", v}, {"elements", n}});
  j["tetgen"]["volume_bound_trials"] = trials;
  if (c.febemesh.ok && c.tetgen.ok) j["element_count_ratio"] = double(c.tetgen.elements) / double(c.febemesh.elements);
  ComparisonOutput report;
  report.command = "compare3d";
  report.title = "febemesh vs TetGen: " + input;
  report.json = std::move(j);
  report.tools = {"febemesh", "tetgen"};
  report.keys = {"elements", "nodes", "boundary_triangles", "wall_seconds", "elements_per_second",
                 "peak_memory_bytes", "min_dihedral_deg", "max_dihedral_deg", "slivers_below_10deg",
                 "min_scaled_jacobian", "mean_scaled_jacobian", "max_radius_ratio", "volume_rel_error",
                 "hausdorff_rel"};
  report.unit = "tets";
  report.tolerance = copt.tolerance;
  report.quality_key = "min_dihedral_deg";
  HistogramPlot mind{"min-dihedral.svg", "Smallest dihedral angle per tetrahedron", "degrees", 0.0, 90.0, 30, {}};
  HistogramPlot maxd{"max-dihedral.svg", "Largest dihedral angle per tetrahedron", "degrees", 60.0, 180.0, 30, {}};
  HistogramPlot rr{"radius-ratio.svg", "Radius ratio R/(3r) per tetrahedron (1 = regular)", "R / 3r", 1.0, 5.0, 32, {}};
  HistogramPlot sj{"scaled-jacobian.svg", "Scaled Jacobian per tetrahedron", "scaled Jacobian", 0.0, 1.0, 25, {}};
  for (const auto& [tool, m] : {std::pair{"febemesh", &c.febemesh}, std::pair{"tetgen", &c.tetgen}}) {
    if (!m->ok) continue;
    mind.series.emplace_back(tool, m->element_min_dihedral_deg);
    maxd.series.emplace_back(tool, m->element_max_dihedral_deg);
    rr.series.emplace_back(tool, m->element_radius_ratio);
    sj.series.emplace_back(tool, m->element_scaled_jacobian);
  }
  report.plots = {std::move(mind), std::move(maxd), std::move(rr), std::move(sj)};
  // Both meshes cut by the same planes: where each tool's slivers lie, and what it left out.
  {
    const Surface surface(read_surface(input));
    std::ostringstream md;
    md << "\n## Sections\n\nBoth meshes cut by the same planes (each cut tetrahedron coloured by its smallest "
          "dihedral angle; black: the surface's cut):\n\n";
    for (const auto& [tool, file, ok] : {std::tuple{"febemesh", "mesh.msh", c.febemesh.ok},
                                         std::tuple{"tetgen", "tetgen.msh", c.tetgen.ok}}) {
      if (!ok) continue;
      const Mesh<3> mesh = read_msh<3>(dir.file(file));
      for (int axis = 0; axis < 3; ++axis) {
        const std::string name = std::string(tool) + "-section-" + "xyz"[axis] + ".svg";
        const std::size_t n = write_section_figure(mesh, surface, axis, dir.file(name), max_section_polygons,
                                                   std::string(tool) == "tetgen" ? "TetGen" : "febemesh");
        md << "- " << tool << ", plane " << "xyz"[axis] << ": ";
        if (n <= max_section_polygons)
          md << "[" << name << "](" << name << ")\n";
        else
          md << n << " polygons, over the limit of " << max_section_polygons << ", not drawn\n";
      }
    }
    report.notes = md.str();
  }
  return finish_comparison(dir, report, quiet);
}

}  // namespace

FEBEMESH_COMMAND(Command{"compare3d", "compare febemesh with TetGen on a closed surface (tables and histograms)", help,
                         run});

}  // namespace febemesh::cli
