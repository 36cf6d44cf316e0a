#pragma once
// One timed end-to-end run of febemesh and of the baseline on the same input, shared by
// bench_mesh2d, bench_mesh3d and scaling (issues 7 and 8).
//
// Ours runs in process: from the parsed input to a written mesh.msh, with the pipeline's own
// stage times. Its memory is the growth of the peak resident set over the run (free heap pages
// are returned with malloc_trim and the peak is reset through /proc/self/clear_refs before it),
// so earlier runs do not hide in it.
// Gmsh runs as a subprocess (dim2/compare_gmsh run_gmsh), inside a forked child of ours so
// that getrusage(RUSAGE_CHILDREN) sees that one Gmsh process only; its wall time includes
// reading the .geo and writing the .msh. TetGen runs through libtet in a forked child
// (dim3/compare_tetgen run_in_child), from reading the .off to writing tetgen.msh.
// Both sides are also timed in CPU seconds: the machine is shared, and CPU time is what a
// loaded machine does not inflate.

#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/process_stats.hpp"
#include "core/quality.hpp"
#include "core/read_msh.hpp"
#include "core/sized_level.hpp"
#include "core/stage_timer.hpp"
#include "core/write_msh.hpp"
#include "dim2/compare_gmsh.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"
#include "dim3/compare_tetgen.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::bench {

namespace fs = std::filesystem;

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct OurRun {
  bool ok = false;
  std::string error;
  double level = 0.0;
  std::size_t elements = 0, nodes = 0;
  double wall_seconds = 0.0, cpu_seconds = 0.0;
  long peak_bytes = 0;  ///< growth of the peak RSS over the run
  std::vector<StageTime> stages;  ///< the pipeline's, then "write mesh.msh"
  double min_dihedral_deg = -1.0;  ///< 3D: the mesh's smallest dihedral angle (-1: not measured)
  double elements_per_second() const { return wall_seconds > 0 ? double(elements) / wall_seconds : 0.0; }
  double elements_per_cpu_second() const { return cpu_seconds > 0 ? double(elements) / cpu_seconds : 0.0; }
  double bytes_per_element() const { return elements ? double(peak_bytes) / double(elements) : 0.0; }
};

/// User + system seconds of the waited-for children so far.
inline double children_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

struct BaselineRun {
  bool ok = false;
  std::string error;
  std::string settings;
  std::size_t elements = 0;
  double wall_seconds = 0.0;
  double cpu_seconds = 0.0;  ///< user + system time of the baseline's process
  long peak_bytes = 0;  ///< Gmsh: its whole process's max RSS; TetGen: peak RSS growth of the child
  int trials = 0;
  double min_dihedral_deg = -1.0;  ///< TetGen: the mesh's smallest dihedral angle, not timed (-1: not measured)
  double elements_per_second() const { return wall_seconds > 0 ? double(elements) / wall_seconds : 0.0; }
  double elements_per_cpu_second() const { return cpu_seconds > 0 ? double(elements) / cpu_seconds : 0.0; }
  double bytes_per_element() const { return elements ? double(peak_bytes) / double(elements) : 0.0; }
};

/// Times `body` (which returns the mesh) plus write_msh into dir/mesh.msh on `threads` threads.
template <int Dim, class Body> OurRun timed_run(const fs::path& dir, int threads, Body&& body) {
  OurRun run;
  fs::create_directories(dir);
  // A fresh file, as the CLI writes (into a new folder): overwriting the last run's mesh.msh
  // (290 MB at flange 1e6) cost ~0.1 s of truncation inside the timed write.
  fs::remove(dir / "mesh.msh");
  // Free heap pages go back to the system first: a run that reuses the pages an earlier, larger
  // run left resident does not raise the peak, and measured 0 B/element (scaling: sphere966 L4
  // after the 2D runs up to 1.4 x 10^6 triangles).
  malloc_trim(0);
  reset_peak_memory();
  const long rss0 = current_memory_bytes();
  const double c0 = cpu_seconds();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    auto [mesh, times] = body();
    const auto tw = std::chrono::steady_clock::now();
    write_msh<Dim>(mesh, dir / "mesh.msh", MshEncoding::Ascii, threads);
    const auto t1 = std::chrono::steady_clock::now();
    run.wall_seconds = std::chrono::duration<double>(t1 - t0).count();
    run.cpu_seconds = cpu_seconds() - c0;
    run.peak_bytes = peak_memory_bytes() - rss0;
    run.elements = mesh.solid.size();
    run.nodes = mesh.points.size();
    run.stages = std::move(times);
    run.stages.push_back({"write mesh.msh", std::chrono::duration<double>(t1 - tw).count()});
    run.ok = true;
  } catch (const std::exception& e) {
    run.error = e.what();
  }
  return run;
}

/// The curve at the level and root scale of the CLI's --size (core level_for_size).
inline SizedLevel sized_curve(dim2::CurveBoundary& curve, double size) {
  const SizedLevel sl = level_for_size<2>(curve.bounding_box(), size);
  curve.set_root_scale(sl.root_scale);
  curve.set_global_level(sl.level);
  return sl;
}

/// mesh2d at `level` (or, with `size` > 0, as the CLI's --size) from the parsed input.
inline OurRun run_ours_2d(const dim2::CurveBoundary& base, double level, int threads, const fs::path& dir,
                          dim2::ElementKind elements = dim2::ElementKind::Tri, double size = 0.0) {
  const SizedLevel sl = size > 0 ? level_for_size<2>(base.bounding_box(), size) : SizedLevel{};
  if (size > 0) level = sl.level;
  OurRun run = timed_run<2>(dir, threads, [&] {
    dim2::CurveBoundary curve = base;
    if (size > 0) curve.set_root_scale(sl.root_scale);
    curve.set_global_level(level);
    dim2::Options2d opt;
    opt.level = level;
    opt.keep_stages = false;
    opt.n_threads = threads;
    opt.elements = elements;
    dim2::Result2d r = dim2::mesh2d(curve, opt);
    return std::pair{std::move(r.fe.mesh), std::move(r.times)};
  });
  run.level = level;
  return run;
}

/// mesh3d at `level` (or, with `size` > 0, at Options3d::size, the CLI's --size) with the CLI's
/// defaults; `target_dihedral_deg` as the CLI's --target-dihedral (the sweeps' aim and the edge
/// removal's bar).
inline OurRun run_ours_3d(const std::string& path, int level, int threads, const fs::path& dir,
                          double target_dihedral_deg = dim3::Options3d{}.target_dihedral_deg, double size = 0.0) {
  double min_deg = -1.0;
  int level_used = level;
  OurRun run = timed_run<3>(dir, threads, [&] {
    dim3::SurfaceBoundary s = dim3::SurfaceBoundary::from_file(path);
    dim3::Options3d opt;
    opt.level = level;
    opt.size = size;
    opt.n_threads = threads;
    dim3::set_target_dihedral(opt, target_dihedral_deg);
    dim3::Result3d r = dim3::mesh3d(s, opt);
    if (r.quality) min_deg = r.quality->min_angle_deg;  // mesh3d's summary, ranking the run
    level_used = r.level;
    return std::pair{std::move(r.fe.mesh), std::move(r.times)};
  });
  run.level = level_used;
  run.min_dihedral_deg = min_deg;
  return run;
}

/// One Gmsh run of size h in a forked child; the child reports through a pipe.
inline BaselineRun gmsh_trial(const dim2::CurveBoundary& curve, double h, const fs::path& dir) {
  BaselineRun b;
  int fd[2];
  if (pipe(fd) != 0) {
    b.error = std::string("pipe: ") + std::strerror(errno);
    return b;
  }
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    std::ostringstream os;
    os.precision(17);
    try {
      const dim2::GmshRun g = dim2::run_gmsh("gmsh", dim2::gmsh_geo(curve, h), dir, "gmsh");
      rusage ru{};
      getrusage(RUSAGE_CHILDREN, &ru);
      std::string err = g.error;
      for (char& c : err)
        if (c == '\n') c = ' ';
      os << g.ok << ' ' << g.mesh.solid.size() << ' ' << g.wall_seconds << ' ' << children_cpu_seconds() << ' '
         << long(ru.ru_maxrss) * 1024 << ' ' << err;
    } catch (const std::exception& e) {
      os << "0 0 0 0 0 " << e.what();
    }
    const std::string s = os.str();
    if (write(fd[1], s.data(), s.size()) < 0) _exit(2);
    _exit(0);
  }
  close(fd[1]);
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = read(fd[0], buf, sizeof buf)) > 0;) text.append(buf, std::size_t(n));
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  std::istringstream is(text);
  int ok = 0;
  if (!(is >> ok >> b.elements >> b.wall_seconds >> b.cpu_seconds >> b.peak_bytes)) {
    b.error = "the Gmsh child died";
    return b;
  }
  std::getline(is >> std::ws, b.error);
  b.ok = ok != 0;
  return b;
}

/// Gmsh at `target` triangles (+-tolerance): uniform size h from the area, rescaled by the
/// square root of the count ratio.
inline BaselineRun run_gmsh_matched(const dim2::CurveBoundary& curve, std::size_t target, const fs::path& dir,
                                    double tolerance = 0.2, int max_trials = 4) {
  fs::create_directories(dir);
  double h = std::sqrt(4.0 * curve.area() / (std::sqrt(3.0) * double(target)));
  BaselineRun best;
  for (int t = 0; t < max_trials; ++t) {
    BaselineRun b = gmsh_trial(curve, h, dir);
    b.trials = t + 1;
    std::ostringstream s;
    s << "gmsh -2 -nt 1, uniform size h = " << std::setprecision(4) << h;
    b.settings = s.str();
    best = b;
    if (!b.ok || b.elements == 0) break;
    const double n = double(b.elements);
    if (std::abs(n - double(target)) <= tolerance * double(target)) break;
    h *= std::sqrt(n / double(target));
  }
  return best;
}

/// TetGen (-pq1.414/10, volume bound rescaled) at `target` tets (+-tolerance), each trial in a
/// forked child.
inline BaselineRun run_tetgen_matched(const std::string& path, std::size_t target, double volume,
                                      const fs::path& dir, double tolerance = 0.2, int max_trials = 4) {
  fs::create_directories(dir);
  double bound = 2.0 * std::abs(volume) / double(target);
  BaselineRun best;
  const fs::path out = dir / "tetgen.msh";
  Mesh<3> last;  // the last trial's mesh (the one returned), measured once after the loop
  for (int t = 0; t < max_trials; ++t) {
    std::ostringstream sw;
    sw.precision(6);
    sw << "pq1.414/10a" << bound << "Q";
    const std::string switches = sw.str();
    const double cpu0 = children_cpu_seconds();
    const dim3::ChildResult c = dim3::run_in_child([&] {
      const Mesh<3> m = dim3::tetgen_mesh(dim3::read_surface(path), switches);
      write_msh<3>(m, out);
    });
    BaselineRun b;
    b.trials = t + 1;
    b.settings = "libtet tetrahedralize(\"" + switches + "\")";
    b.ok = c.ok;
    b.error = c.error;
    b.wall_seconds = c.wall_seconds;
    b.cpu_seconds = children_cpu_seconds() - cpu0;
    b.peak_bytes = c.peak_memory_growth_bytes;
    last = c.ok ? read_msh<3>(out) : Mesh<3>{};
    b.elements = last.solid.size();
    best = b;
    if (!b.ok || b.elements == 0) break;
    const double n = double(b.elements);
    if (std::abs(n - double(target)) <= tolerance * double(target)) break;
    bound *= n / double(target);
  }
  if (best.ok && best.elements > 0) best.min_dihedral_deg = summarize_quality<3>(last, 10.0).min_angle_deg;
  return best;
}

/// "1.23e+05"-style compact numbers for tables.
inline std::string sci(double v, int digits = 3) {
  std::ostringstream os;
  os << std::setprecision(digits) << v;
  return os.str();
}

inline std::string fixed(double v, int decimals = 3) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

/// Stage name -> seconds of one run (a stage that repeats, e.g. repairs, is summed).
inline nlohmann::json stages_json(const OurRun& run) {
  nlohmann::json j = nlohmann::json::object();
  for (const StageTime& s : run.stages) j[s.name] = j.value(s.name, 0.0) + s.seconds;
  return j;
}

/// Our run's size, times and memory (the same keys in 2D and 3D), stages included.
inline nlohmann::json run_json(const OurRun& run) {
  nlohmann::json j = {{"elements", run.elements},
          {"nodes", run.nodes},
          {"wall_seconds", run.wall_seconds},
          {"cpu_seconds", run.cpu_seconds},
          {"elements_per_second", run.elements_per_second()},
          {"peak_bytes", run.peak_bytes},
          {"bytes_per_element", run.bytes_per_element()},
          {"stages", stages_json(run)}};
  if (run.min_dihedral_deg >= 0) j["min_dihedral_deg"] = run.min_dihedral_deg;
  return j;
}

/// A baseline tool's run with the same keys for Gmsh and TetGen.
inline nlohmann::json baseline_json(const BaselineRun& b) {
  nlohmann::json j = {{"ok", b.ok},
          {"error", b.error},
          {"settings", b.settings},
          {"elements", b.elements},
          {"wall_seconds", b.wall_seconds},
          {"cpu_seconds", b.cpu_seconds},
          {"elements_per_second", b.elements_per_second()},
          {"peak_bytes", b.peak_bytes},
          {"bytes_per_element", b.bytes_per_element()},
          {"trials", b.trials}};
  if (b.min_dihedral_deg >= 0) j["min_dihedral_deg"] = b.min_dihedral_deg;
  return j;
}

/// Markdown table of the stage times (seconds, wall) of tagged runs, one column per stage name
/// in order of first appearance.
inline std::string stage_table(const std::vector<std::pair<std::string, OurRun>>& runs) {
  std::vector<std::string> names;
  for (const auto& [tag, run] : runs)
    for (const StageTime& s : run.stages)
      if (std::find(names.begin(), names.end(), s.name) == names.end()) names.push_back(s.name);
  std::ostringstream t;
  t << "| run |";
  for (const auto& n : names) t << " " << n << " |";
  t << "\n|---|";
  for (std::size_t k = 0; k < names.size(); ++k) t << "---|";
  t << "\n";
  for (const auto& [tag, run] : runs) {
    t << "| " << tag << " |";
    for (const auto& n : names) {
      double sum = 0.0;
      for (const StageTime& st : run.stages)
        if (st.name == n) sum += st.seconds;
      t << " " << fixed(sum) << " |";
    }
    t << "\n";
  }
  return t.str();
}

}  // namespace febemesh::bench
