#include "dim3/compare_tetgen.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <tetgen.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/read_msh.hpp"
#include "core/write_msh.hpp"
#include "dim3/fidelity3d.hpp"
#include "dim3/read_surface.hpp"

namespace febemesh::dim3 {
namespace fs = std::filesystem;
namespace {

long status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const std::size_t n = std::strlen(key);
  while (std::getline(in, line))
    if (line.compare(0, n, key) == 0) return std::stol(line.substr(n));
  return 0;
}

void write_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t w = ::write(fd, s.data() + done, s.size() - done);
    if (w <= 0) return;
    done += std::size_t(w);
  }
}

/// Runs `f` with stdout going to a temporary file, or unbuffered to `keep` when given (so that
/// what was printed survives a crash); returns what was printed. TetGen prints its diagnostics
/// with printf before throwing.
template <typename F> std::string capture_stdout(F&& f, const std::string& keep) {
  std::fflush(stdout);
  FILE* tmp = keep.empty() ? std::tmpfile() : std::fopen(keep.c_str(), "w+");
  const int saved = ::dup(STDOUT_FILENO);
  if (tmp) ::dup2(::fileno(tmp), STDOUT_FILENO);
  if (tmp && !keep.empty()) std::setvbuf(stdout, nullptr, _IONBF, 0);
  auto restore = [&] {
    std::fflush(stdout);
    if (saved >= 0) {
      ::dup2(saved, STDOUT_FILENO);
      ::close(saved);
    }
  };
  std::string text;
  try {
    f();
  } catch (...) {
    restore();
    if (tmp) std::fclose(tmp);
    throw;
  }
  restore();
  if (tmp) {
    std::rewind(tmp);
    char buf[4096];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, tmp)) > 0) text.append(buf, n);
    std::fclose(tmp);
  }
  return text;
}

}  // namespace

std::string tetgen_code_meaning(int code) {
  switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "a self-intersection was detected";
    case 4: return "a very small input feature size was detected";
    case 5: return "two very close input facets were detected";
    case 10: return "an input error was detected";
    default: return "unknown error";
  }
}

Mesh<3> tetgen_mesh(const TriangleSoup& soup, const std::string& switches, const std::string& log_path) {
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = int(soup.vertices.size());
  in.pointlist = new REAL[soup.vertices.size() * 3];
  for (std::size_t v = 0; v < soup.vertices.size(); ++v)
    for (int d = 0; d < 3; ++d) in.pointlist[3 * v + std::size_t(d)] = soup.vertices[v][d];
  in.numberoffacets = int(soup.triangles.size());
  in.facetlist = new tetgenio::facet[soup.triangles.size()];
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    tetgenio::facet& f = in.facetlist[t];
    tetgenio::init(&f);
    f.numberofpolygons = 1;
    f.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&f.polygonlist[0]);
    f.polygonlist[0].numberofvertices = 3;
    f.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) f.polygonlist[0].vertexlist[k] = soup.triangles[t][std::size_t(k)];
  }
  std::vector<char> sw(switches.begin(), switches.end());
  sw.push_back('\0');
  int code = 0;
  const std::string printed = capture_stdout([&] {
    try {
      tetrahedralize(sw.data(), &in, &out);
    } catch (int c) {  // libtet's way of failing (terminatetetgen)
      code = c;
    }
  }, log_path);
  if (code != 0)
    throw TetgenError(code, "TetGen error code " + std::to_string(code) + " (" + tetgen_code_meaning(code) + ")" +
                                (printed.empty() ? std::string() : ", TetGen printed:\n" + printed));
  Mesh<3> m;
  const int base = out.firstnumber;
  for (int v = 0; v < out.numberofpoints; ++v)
    m.add_point(Point<3>(out.pointlist[3 * v], out.pointlist[3 * v + 1], out.pointlist[3 * v + 2]));
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    std::array<VertexId, 4> n;
    for (int k = 0; k < 4; ++k) n[std::size_t(k)] = VertexId{out.tetrahedronlist[t * out.numberofcorners + k] - base};
    // TetGen's orientation convention is the mirror of Gmsh's: make every tet positive.
    const std::array<Point<3>, 4> p{m.point(n[0]), m.point(n[1]), m.point(n[2]), m.point(n[3])};
    if (signed_measure<3>(ElemType::Tet4, std::span<const Point<3>>(p)) < 0) std::swap(n[2], n[3]);
    m.solid.add(ElemType::Tet4, n.data(), 4);
  }
  for (int f = 0; f < out.numberoftrifaces; ++f) {
    const VertexId n[3] = {VertexId{out.trifacelist[3 * f] - base}, VertexId{out.trifacelist[3 * f + 1] - base},
                           VertexId{out.trifacelist[3 * f + 2] - base}};
    m.interface.add(ElemType::Tri3, n, 3);
  }
  return m;
}

MeshMetrics3d measure_mesh3d(const Mesh<3>& mesh, const SurfaceBoundary& surface) {
  MeshMetrics3d m;
  m.ok = true;
  m.elements = mesh.solid.size();
  m.nodes = mesh.points.size();
  m.boundary_triangles = mesh.interface.size();
  const QualitySummary q = summarize_quality<3>(mesh, 10.0);
  m.min_dihedral_deg = q.min_angle_deg;
  m.max_dihedral_deg = q.max_angle_deg;
  m.slivers_below_10deg = q.n_slivers;
  m.min_scaled_jacobian = q.min_scaled_jacobian;
  m.mean_scaled_jacobian = q.mean_scaled_jacobian;
  m.max_radius_ratio = q.max_radius_ratio;
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    const auto pts = element_points<3>(mesh.solid, ElemId{std::int32_t(e)}, mesh.points);
    const ElementQuality eq = element_quality<3>(mesh.solid.type[e], pts.span());
    m.element_min_dihedral_deg.push_back(eq.min_angle_deg);
    m.element_max_dihedral_deg.push_back(eq.max_angle_deg);
    m.element_radius_ratio.push_back(eq.radius_ratio);
    m.element_scaled_jacobian.push_back(eq.scaled_jacobian);
  }
  const Fidelity3d fid = measure_fidelity(mesh, surface);
  m.volume_rel_error = fid.volume_rel_error;
  m.hausdorff_rel = fid.hausdorff_rel;
  return m;
}

ChildResult run_in_child(const std::function<void()>& job) {
  ChildResult r;
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    ::close(fds[0]);
    // A crash is the child's report (the parent sees the signal), not the caller's handlers'
    // business (e.g. a test framework's, which would print a failure from the child).
    for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
    {  // Reset the high-water mark so that VmHWM measures this job only (Linux >= 4.0).
      std::ofstream clear("/proc/self/clear_refs");
      clear << "5";
    }
    const long rss0 = status_kb("VmRSS:");
    std::string msg;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      job();
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::ostringstream os;
      os.precision(17);
      os << "ok " << s << " " << (status_kb("VmHWM:") - rss0) * 1024 << "\n";
      msg = os.str();
    } catch (const std::exception& e) {
      msg = std::string("error\n") + e.what();
    } catch (int code) {
      msg = "error\nuncaught int " + std::to_string(code);
    }
    write_all(fds[1], msg);
    ::close(fds[1]);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string text;
  char buf[4096];
  ssize_t n = 0;
  while ((n = ::read(fds[0], buf, sizeof buf)) != 0) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    text.append(buf, std::size_t(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (text.rfind("ok ", 0) == 0) {
    std::istringstream in(text.substr(3));
    in >> r.wall_seconds >> r.peak_memory_growth_bytes;
    r.ok = true;
  } else if (text.rfind("error\n", 0) == 0) {
    r.error = text.substr(6);
  } else if (WIFSIGNALED(status)) {
    r.error = "crashed with signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  } else {
    r.error = "the child process ended without a report (status " + std::to_string(status) + ")";
  }
  return r;
}

namespace {

/// A tool's metrics after its run in a child: its .msh read back and measured (so both tools
/// are measured by the same code), or its error verbatim.
MeshMetrics3d child_metrics(const ChildResult& run, const fs::path& msh, const SurfaceBoundary& surface,
                            const std::string& settings) {
  MeshMetrics3d m;
  if (run.ok) {
    m = measure_mesh3d(read_msh<3>(msh), surface);
    m.wall_seconds = run.wall_seconds;
    m.elements_per_second = double(m.elements) / run.wall_seconds;
    m.peak_memory_bytes = run.peak_memory_growth_bytes;
  } else {
    m.ok = false;
    m.error = run.error;
  }
  m.settings = settings;
  return m;
}

}  // namespace

Comparison3d compare_with_tetgen(const std::string& surface_path, const Options3d& opt,
                                 const CompareOptions3d& copt, const fs::path& out) {
  Comparison3d c;
  const SurfaceBoundary surface = SurfaceBoundary::from_file(surface_path);
  {
    std::ostringstream s;
    s << "mesh3d level " << opt.level << " + " << opt.extra_levels << " extra, " << opt.smoothing_iterations
      << " smoothing iterations, " << opt.n_threads << " thread(s); timed from reading the file to writing mesh.msh";
    c.febemesh.settings = s.str();
  }
  const fs::path ours = out / "mesh.msh";
  const ChildResult rf = run_in_child([&] {
    SurfaceBoundary s = SurfaceBoundary::from_file(surface_path);
    const Result3d r = mesh3d(s, opt);
    write_msh<3>(r.fe.mesh, ours);
  });
  c.febemesh = child_metrics(rf, ours, surface, c.febemesh.settings);

  const double target = c.febemesh.ok ? double(c.febemesh.elements) : 0.0;
  // With -q the mean tet volume is well below the bound; start at twice the mean ours has.
  double bound = target > 0 ? 2.0 * std::abs(surface.volume()) / target : 0.0;
  const fs::path theirs = out / "tetgen.msh";
  ChildResult rt;
  for (int it = 0; it < std::max(1, copt.max_iterations); ++it) {
    std::ostringstream sw;
    sw.precision(6);
    sw << "pq" << copt.quality;
    if (bound > 0) sw << "a" << bound;
    sw << "Q";
    c.tetgen_switches = sw.str();
    const fs::path log = out / "tetgen.log";
    rt = run_in_child([&] {
      const Mesh<3> m = tetgen_mesh(read_surface(surface_path), c.tetgen_switches, log.string());
      write_msh<3>(m, theirs);
    });
    if (!rt.ok && rt.error.rfind("crashed", 0) == 0) {
      // libtet 1.5 can crash in its own cleanup while failing, before its error code reaches
      // us: what it printed is what there is to report.
      std::ifstream in(log);
      std::ostringstream printed;
      printed << in.rdbuf();
      rt.error = "TetGen " + rt.error + (printed.str().empty() ? std::string(", printing nothing")
                                                               : ", after printing:\n" + printed.str());
    }
    if (!rt.ok || target <= 0) break;
    const Mesh<3> m = read_msh<3>(theirs);
    const double n = double(m.solid.size());
    c.tetgen_trials.emplace_back(bound, m.solid.size());
    if (std::abs(n - target) <= copt.tolerance * target) break;
    bound *= n / target;
  }
  c.tetgen = child_metrics(rt, theirs, surface,
                           "libtet tetrahedralize(\"" + c.tetgen_switches +
                               "\") in process; timed from reading the file to writing tetgen.msh");
  return c;
}

}  // namespace febemesh::dim3
