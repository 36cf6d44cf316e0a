// febemesh mesh2d: the paper's general algorithm on a 2D input (native JSON, SVG, .poly).

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli/args.hpp"
#include "cli/command.hpp"
#include "cli/limit_hint.hpp"
#include "cli/progress.hpp"
#include "cli/size_option.hpp"
#include "core/atomic_output.hpp"
#include "core/error.hpp"
#include "core/process_stats.hpp"
#include "core/validate.hpp"
#include "core/write_msh.hpp"
#include "core/write_vtu.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/figures2d.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/report2d.hpp"

namespace febemesh::cli {
namespace {

namespace fs = std::filesystem;
using namespace febemesh::dim2;

const char* const help = R"(usage: febemesh mesh2d INPUT -o DIR [options]

Meshes the solid bounded by the closed curves of INPUT (native .json B-spline loops, .svg paths,
Triangle .poly) with the paper's modified quadtree: interior quadrants, boundary quadrants by
projection onto the curve, corner pulling, Laplacian smoothing, a BE mesh on the curve and an FE
mesh from templates that share its nodes.

options:
  -o, --output DIR      output folder (written atomically; an earlier run's folder is
                        replaced, a folder holding other files refused)
  --level N             mesh control level at the curve (quadrant size = root / 2^N); default:
                        the file's levels, else automatic from curvature and thickness
  --size H              instead of --level: the quadrants' side at the curve, in the input's
                        units (the level whose quadrants are no larger, in a root square
                        enlarged by less than 2x so that they are H; the element count then
                        follows H instead of 4x steps; the file's own levels keep their sizes)
  --elements KIND       tri (default) | quad | mixed
  --smooth N            Laplacian smoothing iterations (default 4, as the paper)
  --slide               let boundary nodes slide along the curve while smoothing
  --buffer F            drop interior quadrants nearer the curve than F x their size (default 0.35)
  --max-level N         finest level allowed, repairs included (default 16)
  --max-cells N         refuse trees larger than N quadrants (default 20000000)
  --threads N           threads for refinement, classification, smoothing and output
                        (default: all cores); the mesh is the same byte for byte whatever N
  --figures MODE        all | none | auto (default): auto draws the stage figures when the mesh
                        has at most 20000 elements; above, only figures/00-geometry.svg and a
                        figures/README.txt saying why (SVGs of 10^5 quadrants are unreadable,
                        tens of MB, and took longer to write than the mesh)
  --no-figures          same as --figures none
  --binary              write mesh.msh as MSH 4.1 binary (faster to write and read, not
                        smaller: every tag takes 8 bytes) and mesh.vtu with its arrays as
                        raw appended binary (faster, about half the size)
  --no-validate         skip the final validation (benchmarks)
  --quiet               no progress on stderr

outputs in DIR: mesh.msh (Gmsh MSH 4.1; physical groups "solid" and "interface"), mesh.vtu,
report.json, figures/*.svg (one per stage of the paper, see --figures).
exit status: 0 success, 1 bad input, 2 bad usage.
)";

/// --figures auto: stage figures up to this many FE elements.
constexpr std::size_t auto_figures_max_elements = 20000;

/// Refuses a level whose mesh would exhaust memory, before building anything.
void check_budget(const CurveBoundary& curve, double level, std::size_t max_cells) {
  if (level < 0) return;
  double perimeter = 0.0;
  for (int l = 0; l < curve.n_loops(); ++l) perimeter += curve.length(l);
  const Box<2> root = curve.root_box();
  const double h = (root.hi[0] - root.lo[0]) / std::ldexp(1.0, static_cast<int>(std::ceil(level)));
  const double estimate = 6.0 * perimeter / h + 16.0;  // boundary band plus the graded interior
  if (estimate > static_cast<double>(max_cells)) {
    std::ostringstream os;
    os.precision(3);
    os << "level " << level << " would need about " << estimate << " quadrants (~" << estimate * 400 / 1e9
       << " GB) which exceeds the limit of " << max_cells << " (--max-cells)";
    throw LimitError(os.str());
  }
}

int run(const std::vector<std::string>& argv) {
  const Args args(argv, {"--slide", "--no-figures", "--no-validate", "--quiet", "--binary"},
                  {"-o", "--output", "--level", "--size", "--elements", "--smooth", "--buffer", "--max-level", "--max-cells",
                   "--threads", "--figures"});
  args.expect_positional({"INPUT"});
  const std::string input = args.positional()[0];
  const std::string out = args.value("-o").value_or(args.value_or("--output", ""));
  if (out.empty()) throw UsageError("missing -o DIR");
  check_output_folder(out);  // before the run: never replaces a folder febemesh did not write

  Options2d opt;
  opt.level = args.real_or("--level", no_level, 0, 28);
  const double size = size_option(args);
  opt.elements = element_kind_from(args.choice_or("--elements", "tri", {"tri", "quad", "mixed"}));
  opt.smoothing_iterations = args.int_or("--smooth", 4, 0, 1000);
  opt.slide_boundary = args.has("--slide");
  opt.buffer = args.real_or("--buffer", 0.35, 0.0, 0.95);
  opt.max_level = args.int_or("--max-level", 16, 1, 28);
  opt.max_cells = static_cast<std::size_t>(args.real_or("--max-cells", 2e7, 1e2, 1e10));
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  opt.n_threads = args.int_or("--threads", hw, 1, 256);
  const std::string figures =
      args.has("--no-figures") ? "none" : args.choice_or("--figures", "auto", {"all", "none", "auto"});
  opt.keep_stages = figures != "none";
  if (figures == "auto") opt.keep_stages_max_elements = auto_figures_max_elements;
  const MshEncoding encoding = args.has("--binary") ? MshEncoding::Binary : MshEncoding::Ascii;
  const bool quiet = args.has("--quiet");

  const auto start = std::chrono::steady_clock::now();
  const Progress progress("mesh2d", quiet);
  progress("reading " + input);
  RunInfo info;
  const auto since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  Domain domain = read_domain(input);
  CurveBoundary curve(std::move(domain));
  if (size > 0) {
    const SizedLevel sl = sized_level<2>(curve.bounding_box(), size, 28, input);
    curve.set_root_scale(sl.root_scale);
    opt.level = sl.level;
    std::ostringstream os;
    os << "--size " << size << ": level " << sl.level << " in a root square " << sl.root_scale << "x the default";
    progress(os.str());
  }
  if (opt.level != no_level) curve.set_global_level(opt.level);
  curve.set_max_level(opt.max_level);
  check_budget(curve, opt.level != no_level ? opt.level : curve.global_level(), opt.max_cells);
  info.steps.push_back({"read", since(start)});

  Result2d r;
  try {
    r = mesh2d(curve, opt, progress);
  } catch (const LimitError& e) {
    throw limit_refusal(input, e);
  }

  // The folder is made before the validation, so that with two threads or more mesh.msh and
  // mesh.vtu are written beside it and the fidelity measures (both only read the mesh; a mesh
  // that fails validation throws below, and the folder is removed). Flange level 9 (callgrind,
  // one thread): the two writers were 1.21 G of the CLI's 6.18 G instructions.
  progress("writing " + out);
  AtomicOutputDir dir(out);
  double t_write = 0.0;
  std::future<void> writing = std::async(opt.n_threads > 1 ? std::launch::async : std::launch::deferred, [&] {
    const auto t0 = std::chrono::steady_clock::now();
    write_msh<2>(r.fe.mesh, dir.file("mesh.msh"), encoding);
    write_vtu<2>(r.fe.mesh, dir.file("mesh.vtu"), encoding == MshEncoding::Binary ? VtuEncoding::Binary : VtuEncoding::Ascii);
    t_write = since(t0);
  });
  auto t0 = std::chrono::steady_clock::now();
  const Fidelity2d fid = measure_fidelity(r.fe, curve);
  info.steps.push_back({"fidelity", since(t0)});

  ValidationReport valid;
  if (!args.has("--no-validate")) {
    progress("validating " + std::to_string(r.fe.mesh.solid.size()) + " elements");
    ValidateOptions<2> vo;
    vo.expected_euler = curve.n_components() - curve.n_holes();
    const Box<2> bb = curve.bounding_box();
    vo.boundary_distance = [&](const Point<2>& p) { return curve.closest_point(p).distance; };
    vo.boundary_tolerance = 1e-10 * (bb.hi - bb.lo).norm();
    vo.n_threads = opt.n_threads;
    t0 = std::chrono::steady_clock::now();
    valid = validate<2>(r.fe.mesh, vo);
    info.steps.push_back({"validation", since(t0)});
  }
  if (!valid.valid && !args.has("--no-validate"))
    throw std::runtime_error("the mesh of " + input + " failed validation (please report):\n" + valid.summary());
  // The quality section's measures, in the run's time (beside the writing on 2+ threads).
  t0 = std::chrono::steady_clock::now();
  const Quality2d quality = measure_quality(r.fe.mesh, curve, opt.n_threads);
  info.steps.push_back({"quality summary", since(t0)});
  writing.get();  // rethrows a write error (one thread: writes now)
  info.steps.push_back({"write mesh.msh and mesh.vtu", t_write});  // beside the checks on 2+ threads
  if (r.stages_kept) write_stage_figures(r, curve, dir.file("figures"));
  else if (opt.keep_stages) write_figures_skipped_note(dir.file("figures"), r.fe.mesh.solid.size(), opt.keep_stages_max_elements);
  if (opt.keep_stages) draw_geometry_figure(curve, dir.file("figures") / "00-geometry.svg");
  info.input = input;
  info.version = FEBEMESH_VERSION;
  info.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  info.peak_memory_bytes = peak_memory_bytes();
  {
    std::ofstream rep(dir.file("report.json"));
    // The CLI's own options (figures, MSH encoding) join the library's in "options".
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(report_json(r, curve, opt, fid, quality, valid, info));
    j["options"]["size"] = size > 0 ? nlohmann::ordered_json(size) : nlohmann::ordered_json(nullptr);
    j["options"]["root_scale"] = curve.root_scale();
    j["options"]["figures"] = figures;
    j["options"]["figures_drawn"] = r.stages_kept;
    j["options"]["msh_encoding"] = encoding == MshEncoding::Binary ? "binary" : "ascii";
    j["options"]["vtu_encoding"] = encoding == MshEncoding::Binary ? "binary" : "ascii";
    rep << j.dump(2) << "\n";
    if (!rep) throw InputError(dir.file("report.json").string() + ": cannot write");
  }
  dir.commit();
  progress(std::to_string(r.fe.mesh.solid.size()) + " FE elements, " + std::to_string(r.fe.mesh.interface.size()) +
           " BE elements, " + std::to_string(r.fe.mesh.points.size()) + " nodes in " +
           (std::ostringstream() << info.total_seconds).str() + " s");
  std::cout << fs::path(out).string() << "\n";
  return exit_ok;
}

}  // namespace

FEBEMESH_COMMAND(Command{"mesh2d", "mesh a 2D solid (FE) and its interface (BE) by the modified quadtree", help, run});

}  // namespace febemesh::cli
