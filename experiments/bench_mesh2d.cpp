// bench_mesh2d: febemesh against Gmsh, end to end, at the same element count (issue 8).
//
// For every input (the bundled parts and a few glyphs) and every target size, untimed runs
// search for the quadrant size (the CLI's --size) whose count is within 5% of it
// (experiments/size_search.hpp). The run at that size is then timed from the parsed input to a
// written mesh.msh (experiments/scaling_runs.hpp); Gmsh meshes the same exact curves
// (dim2/compare_gmsh's .geo) with a uniform size rescaled until its triangle count is within 20%
// of ours. The table gives both speeds, both memories per element and the ratio.
//
// Usage: bench_mesh2d [--sizes 1e4,1e5,1e6] [--inputs a.json,b.svg] [--no-gmsh] [--threads N]
//                     [--memory-budget GB] [--gmsh-max N]
//                     [--elements tri|quad|mixed] [--pin-one-thread]
//   --memory-budget: a size whose estimated peak (bytes/element of the previous size) exceeds
//   it is skipped with a message (default 6 GB: the machine is shared).
//   --gmsh-max: no Gmsh run above this many elements (default 1.2e6; Gmsh takes ~30 s per 10^6).
//   --elements: tri (default), quad or mixed.
//   --levels: run these levels instead of searching sizes for --sizes.
//   --pin-one-thread: with --threads 1, each timed run on the CPU that reads memory fastest
//   just before it (experiments/cpu_probe.hpp: on this VM the two vCPUs differ by up to 1.45x
//   there, and which one is slow changes); every run prints and records that probe.
// Output: tables on stdout, results/bench_mesh2d.md and results/bench_mesh2d.json.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/huge_page_heap.hpp"
#include "experiments/cpu_probe.hpp"
#include "experiments/scaling_runs.hpp"
#include "experiments/size_search.hpp"

using namespace febemesh;
using namespace febemesh::bench;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// The element count of mesh2d at quadrant size `size` (the CLI's --size; -1 where the tree
/// would pass its size limit).
double count_at(const dim2::CurveBoundary& base, double size, dim2::ElementKind elements, int threads) {
  dim2::CurveBoundary curve = base;
  dim2::Options2d opt;
  opt.level = sized_curve(curve, size).level;
  opt.keep_stages = false;
  opt.n_threads = threads;
  opt.elements = elements;
  try {
    return double(dim2::mesh2d(curve, opt).fe.mesh.solid.size());
  } catch (const LimitError&) {
    return -1.0;
  }
}

}  // namespace

int main(int argc, char** argv) {
  febemesh::set_up_heap(argv);  // first: it may start the program again
  std::vector<double> sizes{1e4, 1e5, 1e6};
  const std::string data = FEBEMESH_DATA_DIR, src = FEBEMESH_SOURCE_DIR;
  std::vector<std::string> inputs{src + "/examples/flange.json", src + "/examples/bracket.json",
                                  src + "/examples/naca0012.json", data + "/2d/DejaVuSans-U0041.svg",
                                  data + "/2d/NimbusSans-Regular-U0067.svg"};
  std::vector<double> levels;
  bool gmsh = true;
  int threads = 1;
  dim2::ElementKind elements = dim2::ElementKind::Tri;
  double budget = 6e9, gmsh_max = 1.2e6;
  bool pin_one_thread = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--sizes") {
      sizes.clear();
      for (const auto& s : split(next())) sizes.push_back(std::stod(s));
    } else if (a == "--levels") {
      for (const auto& s : split(next())) levels.push_back(std::stod(s));
    } else if (a == "--inputs") {
      inputs = split(next());
    } else if (a == "--no-gmsh") {
      gmsh = false;
    } else if (a == "--elements") {
      elements = dim2::element_kind_from(next());
    } else if (a == "--threads") {
      threads = std::stoi(next());
    } else if (a == "--memory-budget") {
      budget = std::stod(next()) * 1e9;
    } else if (a == "--gmsh-max") {
      gmsh_max = std::stod(next());
    } else if (a == "--pin-one-thread") {
      pin_one_thread = true;
    } else {
      std::cerr << "usage: bench_mesh2d [--sizes 1e4,1e5,1e6] [--inputs a,b] [--no-gmsh] [--threads N] "
                   "[--memory-budget GB] [--gmsh-max N] [--levels 8,9.4] [--elements tri|quad|mixed] [--pin-one-thread]\n";
      return 2;
    }
  }
  const fs::path res = fs::path(src) / "results";
  const fs::path work = res / "bench_mesh2d";
  fs::create_directories(work);
  // The CPUs' memory speed, before and after the runs (cpu_probe.hpp).
  const std::vector<CpuMemoryProbe> probe_before = probe_cpu_memory();
  std::cout << "machine: " << describe(probe_before) << "\n" << std::flush;

  nlohmann::json jruns = nlohmann::json::array();
  std::ostringstream table, stages_table, skipped;
  table << "| input | target | level | elements | wall s | cpu s | el/s (wall) | el/s (cpu) | peak MB | B/el | Gmsh el "
           "| Gmsh s | Gmsh cpu s | Gmsh el/s | Gmsh el/s (cpu) | Gmsh B/el | ratio (wall) | ratio (cpu) |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::pair<std::string, OurRun>> all;

  for (const std::string& input : inputs) {
    const std::string name = fs::path(input).stem().string();
    std::cout << "== " << name << "\n" << std::flush;
    std::optional<dim2::CurveBoundary> base;
    try {
      base.emplace(dim2::read_domain(input));
    } catch (const std::exception& e) {
      std::cout << "  skipped: " << e.what() << "\n";
      skipped << "- " << name << ": " << e.what() << "\n";
      continue;
    }
    double bytes_per_el = 0.0;
    const std::vector<double>& runs = levels.empty() ? sizes : levels;
    for (const double size_or_level : runs) {
      // --sizes: the target; --levels: no target (the budget check then uses the level's count
      // as the run before it, scaled by 4 per level).
      const bool sized = levels.empty();
      const double target = sized ? size_or_level : 0.0;
      const std::string tag = name + " " + (sized ? sci(target, 2) : "level " + fixed(size_or_level, 2));
      if (sized && bytes_per_el > 0 && bytes_per_el * target > budget) {
        std::ostringstream msg;
        msg << tag << ": skipped, estimated peak " << sci(bytes_per_el * target / 1e9) << " GB > budget "
            << sci(budget / 1e9) << " GB (--memory-budget)";
        std::cout << "  " << msg.str() << "\n";
        skipped << "- " << msg.str() << "\n";
        continue;
      }
      // Levels are real: the control level interpolates the cell size between powers of two.
      double level = size_or_level, size = 0.0;
      if (sized) {
        // Untimed runs from the default square's level-7 quadrant; the count grows about as
        // size^-2 (a uniform level at the curve, a 2D tree).
        const SizeAim aim = aim_size(base->root_box().extent()[0] / 128.0, target, 0.05, -2.0, -3.0, -1.0,
                                     [&](double h) { return count_at(*base, h, elements, threads); });
        size = aim.size;
        level = level_for_size<2>(base->bounding_box(), size).level;
        std::cout << "  " << tag << ": size " << size << ", level " << level << " (" << aim.runs << " untimed runs; "
                  << std::int64_t(aim.count) << " elements)\n"
                  << std::flush;
      }
      // --pin-one-thread: on the CPU that reads memory fastest just before the run.
      const OurRun run = [&] {
        const PinnedTo pin(pin_one_thread && threads == 1 ? fastest_cpu(probe_cpu_memory()) : -1);
        return run_ours_2d(*base, level, threads, work / name, elements, size);
      }();
      if (!run.ok) {
        std::cout << "  " << tag << ": febemesh failed: " << run.error << "\n";
        skipped << "- " << tag << ": febemesh failed: " << run.error << "\n";
        continue;
      }
      bytes_per_el = run.bytes_per_element();
      BaselineRun g;
      if (gmsh && double(run.elements) <= gmsh_max) g = run_gmsh_matched(*base, run.elements, work / name);
      const double ratio = g.ok ? run.elements_per_second() / g.elements_per_second() : 0.0;
      const double cpu_ratio = g.ok ? (double(run.elements) / run.cpu_seconds) / g.elements_per_cpu_second() : 0.0;
      std::ostringstream row;
      row << "| " << name << " | " << (sized ? sci(target, 2) : "-") << " | " << level
          << (sized ? " (size " + sci(size, 3) + ")" : std::string()) << " | " << run.elements << " | "
          << fixed(run.wall_seconds) << " | " << fixed(run.cpu_seconds) << " | " << sci(run.elements_per_second())
          << " | " << sci(double(run.elements) / run.cpu_seconds) << " | " << fixed(run.peak_bytes / 1e6, 1) << " | "
          << fixed(run.bytes_per_element(), 0) << " | ";
      if (g.ok)
        row << g.elements << " | " << fixed(g.wall_seconds) << " | " << fixed(g.cpu_seconds) << " | " << sci(g.elements_per_second()) << " | "
            << sci(g.elements_per_cpu_second()) << " | "
            << fixed(g.bytes_per_element(), 0) << " | " << fixed(ratio, 1) << "x | " << fixed(cpu_ratio, 1) << "x |";
      else
        row << "- | - | - | - | - | - | " << (gmsh && double(run.elements) <= gmsh_max ? "Gmsh failed: " + g.error : "not run")
            << " | - |";
      table << row.str() << "\n";
      std::cout << row.str() << "\n" << std::flush;

      nlohmann::json j;
      j["input"] = name;
      if (sized) j["target"] = target, j["size"] = size;
      j["level"] = level;
      j["threads"] = threads;
      j.update(run_json(run));
      if (g.trials > 0) {
        j["gmsh"] = baseline_json(g);
        j["speed_ratio"] = ratio;
        j["speed_ratio_cpu"] = cpu_ratio;
      }
      jruns.push_back(j);
      all.emplace_back(tag, run);
    }
  }

  stages_table << stage_table(all);
  const std::vector<CpuMemoryProbe> probe_after = probe_cpu_memory();
  std::cout << "machine: " << describe(probe_after) << "\n";

  std::ostringstream md;
  md << "# bench_mesh2d: febemesh vs Gmsh, end to end\n\n"
     << "Machine: before the runs " << describe(probe_before) << "; after them " << describe(probe_after)
     << (pin_one_thread && threads == 1 ? "; our runs pinned to the faster CPU of a probe just before each" : "") << ".\n\n"
     << "Ours: mesh2d from the parsed input to a written mesh.msh (ASCII), " << threads
     << " thread(s), in process; peak = growth of the peak RSS over the run. Gmsh: `gmsh -2 -nt 1` on the same exact "
        "curves, uniform size rescaled to our element count (+-20%), whole process (reading the .geo, writing the "
        ".msh; its B/el includes the program's own ~30 MB). Speed ratio = our el/s (wall) / Gmsh el/s (wall). The "
        "machine is shared: the cpu column is what load does not inflate.\n\n"
     << table.str() << "\n## Stage times (seconds, wall)\n\n" << stages_table.str();
  if (!skipped.str().empty()) md << "\n## Skipped\n\n" << skipped.str();
  std::ofstream(res / "bench_mesh2d.md") << md.str();
  std::ofstream(res / "bench_mesh2d.json") << nlohmann::json{{"runs", jruns},
                                                             {"cpu_memory_before", probe_json(probe_before)},
                                                             {"cpu_memory_after", probe_json(probe_after)},
                                                             {"pin_one_thread", pin_one_thread && threads == 1}}
                                                  .dump(2)
                                           << "\n";
  std::cout << "\n" << stages_table.str() << "\nwrote " << (res / "bench_mesh2d.md").string() << "\n";
  return 0;
}
