// bench_mesh3d: febemesh against TetGen, end to end, at the same tet count (issue 8).
//
// For every surface and every level, mesh3d runs in process from reading the .off to a written
// mesh.msh (experiments/scaling_runs.hpp: stage times, peak RSS growth); TetGen (libtet,
// -pq1.414/10 with a volume bound rescaled until its tet count is within 20% of ours) runs in
// a forked child from reading the .off to writing tetgen.msh (dim3/compare_tetgen). 3D levels
// are integers, so the sizes step by about 4-8x per level; --tets names tet counts instead, and
// untimed runs search the octant size (mesh3d's --size, Options3d::size) that gives each within
// 10% (experiments/size_search.hpp).
//
// Usage: bench_mesh3d [--levels 3,4,5 | --tets 1e4,1e5,1e6,5e6] [--inputs a.off,b.off | --all-surfaces]
//                     [--no-tetgen] [--threads 1,2] [--repeat R] [--memory-budget GB] [--target-dihedral DEG]
//                     [--pin-one-thread]
// --pin-one-thread: each one-thread run on the CPU that reads memory fastest just before it
// (experiments/cpu_probe.hpp: on this VM the two vCPUs differ by up to 1.45x there, and which
// one is slow changes); every run prints and records that probe, before and after the runs.
// --target-dihedral: the CLI's option of that name (the optimisation's aim, default 30). Both
// tools' smallest dihedral angles are in the table (measured after the timed runs).
// The default input is sphere966 (no repairs: the stages' own speed); --all-surfaces takes every
// closed surface of the shared data (every .off there but open-cylinder, which must be
// refused), the machined parts whose refused tries and repairs cost most of their time. A
// failing input is reported with mesh3d's message and the run goes on.
// With several thread counts (--threads 1,2) every level runs once per count, R times in turn
// (1, 2, 1, 2, ...: load on a shared machine hits both alike), and a threads table gives each
// count's fastest run, its stage times, the speedup over the first count and whether mesh.msh
// is the same bytes. The main table and TetGen use the first count.
// Output: tables on stdout, results/bench_mesh3d.md and results/bench_mesh3d.json.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/huge_page_heap.hpp"
#include "experiments/cpu_probe.hpp"
#include "experiments/scaling_runs.hpp"
#include "experiments/size_search.hpp"

using namespace febemesh;
using namespace febemesh::bench;

namespace {

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// The tets of mesh3d at octant size `size` (Options3d::size, the CLI's --size); 0 where refused.
double count_at(dim3::SurfaceBoundary& s, double size, int threads, double target_deg) {
  dim3::Options3d opt;
  opt.size = size;
  opt.n_threads = threads;
  dim3::set_target_dihedral(opt, target_deg);
  try {
    return double(dim3::mesh3d(s, opt).fe.mesh.solid.size());
  } catch (const std::exception&) {
    return 0.0;  // refused (a size too small for the tree's limit is the usual one)
  }
}

}  // namespace

int main(int argc, char** argv) {
  febemesh::set_up_heap(argv);  // first: it may start the program again
  std::vector<int> levels{3, 4, 5};
  std::vector<double> tets;  // --tets: counts instead of levels
  const std::string data = FEBEMESH_DATA_DIR, src = FEBEMESH_SOURCE_DIR;
  std::vector<std::string> inputs{data + "/3d/sphere966.off"};
  bool tetgen = true;
  std::vector<int> thread_counts{1};
  int repeat = 1;
  double budget = 6e9;
  double target_deg = dim3::Options3d{}.target_dihedral_deg;
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
    if (a == "--levels") {
      levels.clear();
      for (const auto& s : split(next())) levels.push_back(std::stoi(s));
    } else if (a == "--tets") {
      for (const auto& s : split(next())) tets.push_back(std::stod(s));
    } else if (a == "--inputs") {
      inputs = split(next());
    } else if (a == "--all-surfaces") {
      inputs.clear();
      for (const auto& e : fs::directory_iterator(fs::path(data) / "3d"))
        if (e.path().extension() == ".off" && e.path().stem() != "open-cylinder") inputs.push_back(e.path().string());
      std::sort(inputs.begin(), inputs.end());
    } else if (a == "--no-tetgen") {
      tetgen = false;
    } else if (a == "--threads") {
      thread_counts.clear();
      for (const auto& s : split(next())) thread_counts.push_back(std::max(1, std::stoi(s)));
      if (thread_counts.empty()) thread_counts.push_back(1);
    } else if (a == "--repeat") {
      repeat = std::max(1, std::stoi(next()));
    } else if (a == "--memory-budget") {
      budget = std::stod(next()) * 1e9;
    } else if (a == "--target-dihedral") {
      target_deg = std::clamp(std::stod(next()), 0.0, 35.0);
    } else if (a == "--pin-one-thread") {
      pin_one_thread = true;
    } else {
      std::cerr << "usage: bench_mesh3d [--levels 3,4,5 | --tets 1e4,1e5] [--inputs a.off,b.off | --all-surfaces] [--no-tetgen] "
                   "[--threads 1,2] [--repeat R] [--memory-budget GB] [--target-dihedral DEG] [--pin-one-thread]\n";
      return 2;
    }
  }
  const fs::path res = fs::path(src) / "results";
  const fs::path work = res / "bench_mesh3d";
  fs::create_directories(work);
  // The CPUs' memory speed, before and after the runs (cpu_probe.hpp: on this VM one vCPU
  // reads memory up to 1.45x slower than the other, and which one changes).
  const std::vector<CpuMemoryProbe> probe_before = probe_cpu_memory();
  std::cout << "machine: " << describe(probe_before) << "\n" << std::flush;

  nlohmann::json jruns = nlohmann::json::array(), jthreads = nlohmann::json::array();
  std::ostringstream table, stages_table, skipped;
  table << "| input | level | tets | wall s | cpu s | tets/s (wall) | tets/s (cpu) | peak MB | B/tet | min dihedral | TetGen tets | "
           "TetGen s | TetGen cpu s | TetGen tets/s | TetGen tets/s (cpu) | TetGen B/tet | TetGen min dihedral | ratio (wall) | "
           "ratio (cpu) |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::pair<std::string, OurRun>> all;
  const int threads = thread_counts.front();
  std::ostringstream threads_table;
  threads_table << "| input | level | threads | runs | wall s | cpu s | cpu / wall | speedup (wall) | same mesh.msh |\n"
                   "|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::pair<std::string, OurRun>> all_threads;

  for (const std::string& input : inputs) {
    const std::string name = fs::path(input).stem().string();
    std::cout << "== " << name << "\n" << std::flush;
    double volume = 0.0;
    try {
      volume = dim3::SurfaceBoundary::from_file(input).volume();
    } catch (const std::exception& e) {
      std::cout << "  skipped: " << e.what() << "\n";
      skipped << "- " << name << ": " << e.what() << "\n";
      continue;
    }
    std::size_t previous = 0;
    double bytes_per_el = 0.0;
    // Levels, or with --tets target counts (level 0 until the search gives a size).
    std::vector<std::pair<int, double>> specs;
    for (const int level : levels)
      if (tets.empty()) specs.emplace_back(level, 0.0);
    for (const double n : tets) specs.emplace_back(0, n);
    for (const auto& [level_asked, target] : specs) {
      int level = level_asked;
      std::string tag = name + (target > 0 ? " " + sci(target, 2) + " tets" : " L" + std::to_string(level));
      // The next level has up to 8x the tets of this one; a target, its own count.
      const double expected = target > 0 ? target : 8.0 * double(previous);
      if (bytes_per_el > 0 && bytes_per_el * expected > budget) {
        std::ostringstream msg;
        msg << tag << ": skipped, estimated peak up to " << sci(bytes_per_el * expected / 1e9) << " GB > budget "
            << sci(budget / 1e9) << " GB (--memory-budget)";
        std::cout << "  " << msg.str() << "\n";
        skipped << "- " << msg.str() << "\n";
        continue;
      }
      double size = 0.0;
      if (target > 0) {
        // Untimed runs from the default cube's level-4 octant; the count grows as size^-2 to
        // size^-3 (the surface's octants, then the volume's).
        dim3::SurfaceBoundary s = dim3::SurfaceBoundary::from_file(input);
        const SizeAim aim = aim_size(s.root_box().extent()[0] / 16.0, target, 0.1, -2.5, -3.5, -1.5,
                                     [&](double h) { return count_at(s, h, threads, target_deg); });
        size = aim.size;
        std::cout << "  " << tag << ": size " << aim.size << " (" << aim.runs << " untimed runs; " << std::int64_t(aim.count)
                  << " tets)\n"
                  << std::flush;
      }
      // Each thread count's fastest of `repeat` runs, the counts taking turns.
      std::vector<OurRun> best(thread_counts.size());
      for (int r = 0; r < repeat; ++r)
        for (std::size_t k = 0; k < thread_counts.size(); ++k) {
          const fs::path dir = thread_counts.size() > 1 ? work / name / ("threads" + std::to_string(thread_counts[k])) : work / name;
          // --pin-one-thread: on the CPU that reads memory fastest just before the run.
          const PinnedTo pin(pin_one_thread && thread_counts[k] == 1 ? fastest_cpu(probe_cpu_memory()) : -1);
          OurRun one = run_ours_3d(input, level, thread_counts[k], dir, target_deg, size);
          if (!one.ok || !best[k].ok || one.wall_seconds < best[k].wall_seconds) best[k] = std::move(one);
        }
      const OurRun& run = best.front();
      if (run.ok) level = static_cast<int>(run.level);  // the level the size gave
      const std::string level_cell = std::to_string(level) + (size > 0 ? " (size " + sci(size, 3) + ")" : "");
      if (thread_counts.size() > 1 && run.ok) {
        const std::string first = read_text(work / name / ("threads" + std::to_string(threads)) / "mesh.msh");
        for (std::size_t k = 0; k < thread_counts.size(); ++k) {
          const OurRun& b = best[k];
          if (!b.ok) continue;
          const bool same = read_text(work / name / ("threads" + std::to_string(thread_counts[k])) / "mesh.msh") == first;
          threads_table << "| " << name << " | " << level_cell << " | " << thread_counts[k] << " | " << repeat << " | "
                        << fixed(b.wall_seconds) << " | " << fixed(b.cpu_seconds) << " | " << fixed(b.cpu_seconds / b.wall_seconds, 2)
                        << " | " << fixed(run.wall_seconds / b.wall_seconds, 2) << "x | " << (same ? "yes" : "NO") << " |\n";
          all_threads.emplace_back(tag + " t" + std::to_string(thread_counts[k]), b);
          nlohmann::json jt;
          jt["input"] = name;
          jt["level"] = level;
          if (size > 0) jt["size"] = size;
          jt["threads"] = thread_counts[k];
          jt["repeat"] = repeat;
          jt["same_mesh_as_first"] = same;
          jt.update(run_json(b));
          jthreads.push_back(jt);
        }
      }
      if (!run.ok) {
        std::cout << "  " << tag << ": febemesh failed: " << run.error << "\n";
        skipped << "- " << tag << ": febemesh failed: " << run.error.substr(0, 300) << "\n";
        continue;
      }
      previous = run.elements;
      bytes_per_el = run.bytes_per_element();
      BaselineRun t;
      if (tetgen) t = run_tetgen_matched(input, run.elements, volume, work / name);
      const double ratio = t.ok ? run.elements_per_second() / t.elements_per_second() : 0.0;
      const double cpu_ratio = t.ok ? (double(run.elements) / run.cpu_seconds) / t.elements_per_cpu_second() : 0.0;
      std::ostringstream row;
      row << "| " << name << " | " << level_cell << " | " << run.elements << " | " << fixed(run.wall_seconds) << " | "
          << fixed(run.cpu_seconds) << " | " << sci(run.elements_per_second()) << " | "
          << sci(double(run.elements) / run.cpu_seconds) << " | " << fixed(run.peak_bytes / 1e6, 1) << " | "
          << fixed(run.bytes_per_element(), 0) << " | " << fixed(run.min_dihedral_deg, 2) << " | ";
      if (t.ok)
        row << t.elements << " | " << fixed(t.wall_seconds) << " | " << fixed(t.cpu_seconds) << " | " << sci(t.elements_per_second()) << " | "
            << sci(t.elements_per_cpu_second()) << " | " << fixed(t.bytes_per_element(), 0) << " | "
            << fixed(t.min_dihedral_deg, 2) << " | " << fixed(ratio, 2) << "x | " << fixed(cpu_ratio, 1) << "x |";
      else
        row << "- | - | - | - | - | - | - | " << (tetgen ? "TetGen failed: " + t.error.substr(0, 120) : "not run") << " | - |";
      table << row.str() << "\n";
      std::cout << row.str() << "\n" << std::flush;

      nlohmann::json j;
      j["input"] = name;
      j["level"] = level;
      if (size > 0) j["size"] = size, j["target_tets"] = target;
      j["threads"] = threads;
      j["target_dihedral_deg"] = target_deg;
      j.update(run_json(run));
      if (t.trials > 0) {
        j["tetgen"] = baseline_json(t);
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
  md << "# bench_mesh3d: febemesh vs TetGen, end to end\n\n"
     << "Machine: before the runs " << describe(probe_before) << "; after them " << describe(probe_after)
     << (pin_one_thread ? "; one-thread runs pinned to the faster CPU of a probe just before each" : "") << ".\n\n"
     << "Ours: mesh3d from reading the surface to a written mesh.msh (ASCII), " << threads
     << " thread(s), in process, the optimisation aiming at " << fixed(target_deg, 1)
     << " deg (--target-dihedral); peak = growth of the peak RSS over the run. TetGen: libtet `-pq1.414/10a<vol>Q` in a "
        "forked child from reading the .off to writing tetgen.msh, volume bound rescaled to our tet count (+-20%); "
        "peak = the child's RSS growth. Speed ratio = our tets/s / TetGen tets/s (wall). The machine is shared: "
        "the cpu column is what load does not inflate. Min dihedral: each mesh's smallest dihedral angle in degrees "
        "(ours from mesh3d's own quality summary, TetGen's measured on tetgen.msh after its timed run).\n\n"
     << table.str() << "\n## Stage times (seconds, wall)\n\n" << stages_table.str();
  if (thread_counts.size() > 1)
    md << "\n## Threads (each count's fastest of " << repeat << " alternating runs)\n\n"
       << threads_table.str() << "\n" << stage_table(all_threads);
  if (!skipped.str().empty()) md << "\n## Skipped or failed\n\n" << skipped.str();
  std::ofstream(res / "bench_mesh3d.md") << md.str();
  std::ofstream(res / "bench_mesh3d.json") << nlohmann::json{{"runs", jruns},
                                                             {"threads", jthreads},
                                                             {"cpu_memory_before", probe_json(probe_before)},
                                                             {"cpu_memory_after", probe_json(probe_after)},
                                                             {"pin_one_thread", pin_one_thread}}
                                                  .dump(2)
                                           << "\n";
  std::cout << "\n" << stages_table.str();
  if (thread_counts.size() > 1) std::cout << "\n" << threads_table.str() << "\n" << stage_table(all_threads);
  std::cout << "\nwrote " << (res / "bench_mesh3d.md").string() << "\n";
  return 0;
}
