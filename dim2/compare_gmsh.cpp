#include "dim2/compare_gmsh.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/distance.hpp"
#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/read_msh.hpp"
#include "core/write_msh.hpp"

extern char** environ;

namespace febemesh::dim2 {
namespace fs = std::filesystem;
namespace {

/// Uniform bucket grid of segments for nearest-segment queries (exact: rings are searched until
/// no closer segment can exist).
class SegmentGrid {
 public:
  SegmentGrid(std::vector<std::pair<P2, P2>> segs, double cell) : segs_(std::move(segs)), cell_(cell) {
    box_ = Box<2>::empty();
    for (const auto& [a, b] : segs_) {
      box_.expand(a);
      box_.expand(b);
    }
    for (int d = 0; d < 2; ++d) n_[d] = std::max(1, static_cast<int>(std::ceil((box_.hi[d] - box_.lo[d]) / cell_)));
    cells_.assign(std::size_t(n_[0]) * std::size_t(n_[1]), {});
    for (std::size_t i = 0; i < segs_.size(); ++i) {
      const auto& [a, b] = segs_[i];
      const auto [x0, y0] = index(a.cwiseMin(b));
      const auto [x1, y1] = index(a.cwiseMax(b));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) cells_[std::size_t(y) * std::size_t(n_[0]) + std::size_t(x)].push_back(int(i));
    }
  }

  double distance(const P2& p) const {
    const auto [cx, cy] = index(p);
    double best = std::numeric_limits<double>::infinity();
    const int max_ring = std::max(n_[0], n_[1]) + 1;
    for (int r = 0; r <= max_ring; ++r) {
      // Every segment in ring r is at least (r - 1) cells away (p may lie outside the grid,
      // in which case index() clamps and the bound is still a lower bound).
      if (r > 1 && (r - 1) * cell_ > best) break;
      for (int y = cy - r; y <= cy + r; ++y) {
        if (y < 0 || y >= n_[1]) continue;
        for (int x = cx - r; x <= cx + r; ++x) {
          if (x < 0 || x >= n_[0]) continue;
          if (std::max(std::abs(x - cx), std::abs(y - cy)) != r) continue;
          for (int i : cells_[std::size_t(y) * std::size_t(n_[0]) + std::size_t(x)])
            best = std::min(best, point_segment_distance<2>(p, segs_[std::size_t(i)].first, segs_[std::size_t(i)].second));
        }
      }
    }
    return best;
  }

 private:
  std::pair<int, int> index(const P2& p) const {
    auto clampi = [](double v, int n) { return std::clamp(static_cast<int>(std::floor(v)), 0, n - 1); };
    return {clampi((p[0] - box_.lo[0]) / cell_, n_[0]), clampi((p[1] - box_.lo[1]) / cell_, n_[1])};
  }

  std::vector<std::pair<P2, P2>> segs_;
  double cell_;
  Box<2> box_;
  int n_[2] = {1, 1};
  std::vector<std::vector<int>> cells_;
};

/// Point-in-polygon by winding number over a dense sampling of `loop`.
bool inside_loop(const CurveBoundary& curve, int loop, const P2& p) {
  const int n = int(curve.loops()[std::size_t(loop)].n_pieces()) * 32;
  int winding = 0;
  P2 a = curve.evaluate(loop, 0.0);
  for (int i = 1; i <= n; ++i) {
    const P2 b = curve.evaluate(loop, double(i % n) / 32.0);
    const double cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= p[1] && b[1] > p[1] && cross > 0) ++winding;
    if (a[1] > p[1] && b[1] <= p[1] && cross < 0) --winding;
    a = b;
  }
  return winding != 0;
}

std::string g17(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Gmsh's lines that say what went wrong (with -v 2 it prints errors and warnings only).
std::string error_lines(const std::string& log) {
  std::istringstream in(log);
  std::string line, out;
  while (std::getline(in, line))
    if (line.find("Error") != std::string::npos) out += (out.empty() ? "" : "\n") + line;
  return out;
}

}  // namespace

std::string gmsh_recombination(ElementKind kind) {
  switch (kind) {
    case ElementKind::Tri: return "";
    case ElementKind::Mixed: return "Mesh.RecombineAll = 1;\nMesh.RecombinationAlgorithm = 1;\n";
    case ElementKind::Quad:
      return "Mesh.RecombineAll = 1;\nMesh.RecombinationAlgorithm = 1;\nMesh.SubdivisionAlgorithm = 1;\n";
  }
  return "";
}

double initial_gmsh_size(double area, double target, ElementKind kind) {
  // A uniform size h gives about 4 A / (sqrt(3) h^2) triangles; Blossom recombination pairs most
  // of them (about half as many elements); the all-quad subdivision splits those into four.
  const double per_h2 = kind == ElementKind::Tri ? 4.0 / std::sqrt(3.0) : kind == ElementKind::Mixed ? 2.0 / std::sqrt(3.0) : 8.0 / std::sqrt(3.0);
  return std::sqrt(per_h2 * area / target);
}

double curve_polyline_hausdorff(const CurveBoundary& curve, const std::vector<Point<2>>& points,
                                const Elements& edges) {
  if (edges.empty()) return std::numeric_limits<double>::infinity();
  std::vector<std::pair<P2, P2>> segs;
  std::vector<double> lengths;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const VertexId* v = edges.nodes(ElemId{std::int32_t(e)});
    segs.emplace_back(points[std::size_t(v[0].v)], points[std::size_t(v[1].v)]);
    lengths.push_back((segs.back().second - segs.back().first).norm());
  }
  std::vector<double> sorted = lengths;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
  const double typical = std::max(sorted[sorted.size() / 2], 1e-12);
  const double spacing = typical / 8.0;

  double h = 0.0;
  // Boundary edges -> curve.
  for (const auto& [a, b] : segs)
    for (int s = 0; s <= 4; ++s) h = std::max(h, curve.closest_point(a + (b - a) * (s / 4.0)).distance);
  // Curve -> boundary edges.
  const SegmentGrid grid(std::move(segs), typical);
  for (int l = 0; l < curve.n_loops(); ++l) {
    const int n_pieces = int(curve.loops()[std::size_t(l)].n_pieces());
    for (int i = 0; i < n_pieces; ++i) {
      const double len = curve.arc_length(l, i, i + 1 == n_pieces ? 0.0 : double(i + 1));
      const int n = std::clamp(static_cast<int>(std::ceil(len / spacing)), 16, 1 << 16);
      for (int s = 0; s < n; ++s) h = std::max(h, grid.distance(curve.evaluate(l, i + double(s) / n)));
    }
  }
  return h;
}

MeshMetrics2d measure_mesh2d(const Mesh<2>& mesh, const CurveBoundary& curve) {
  MeshMetrics2d m;
  m.ok = true;
  m.elements = mesh.solid.size();
  m.quads = std::size_t(std::count(mesh.solid.type.begin(), mesh.solid.type.end(), ElemType::Quad4));
  m.nodes = mesh.points.size();
  m.boundary_edges = mesh.interface.size();
  const QualitySummary q = summarize_quality<2>(mesh, 30.0);
  m.min_angle_deg = q.min_angle_deg;
  m.max_angle_deg = q.max_angle_deg;
  m.min_scaled_jacobian = q.min_scaled_jacobian;
  m.mean_scaled_jacobian = q.mean_scaled_jacobian;
  m.below_30deg = q.n_slivers;
  for (std::size_t e = 0; e < mesh.solid.size(); ++e) {
    const auto pts = element_points<2>(mesh.solid, ElemId{std::int32_t(e)}, mesh.points);
    const ElementQuality eq = element_quality<2>(mesh.solid.type[e], pts.span());
    m.element_min_angle_deg.push_back(eq.min_angle_deg);
    m.element_scaled_jacobian.push_back(eq.scaled_jacobian);
  }
  const double exact = curve.area();
  m.area_rel_error = std::abs(solid_measure<2>(mesh) - exact) / exact;
  const Box<2> bb = curve.bounding_box();
  const double diag = (bb.hi - bb.lo).norm();
  m.hausdorff_rel = curve_polyline_hausdorff(curve, mesh.points, mesh.interface) / diag;
  std::vector<std::uint8_t> on_boundary(mesh.points.size(), 0);
  for (const VertexId v : mesh.interface.node) on_boundary[std::size_t(v.v)] = 1;
  double nd = 0.0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (on_boundary[v]) nd = std::max(nd, curve.closest_point(mesh.points[v]).distance);
  m.node_distance_rel = nd / diag;
  return m;
}

std::string gmsh_geo(const CurveBoundary& curve, double h, ElementKind kind) {
  std::ostringstream os;
  os << "// Written by febemesh compare2d: the exact cubic Bezier pieces of every loop.\n";
  os << "h = " << g17(h) << ";\n";
  os << "Mesh.MeshSizeMax = h;\nMesh.MeshSizeFromCurvature = 0;\n";
  os << gmsh_recombination(kind);
  int next_point = 1, next_curve = 1;
  std::vector<std::vector<int>> curves_of(std::size_t(curve.n_loops()));
  for (int l = 0; l < curve.n_loops(); ++l) {
    const Loop& loop = curve.loops()[std::size_t(l)];
    const int n = int(loop.n_pieces());
    // Junction points are shared: piece i ends where piece i + 1 starts.
    std::vector<int> junction(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      junction[std::size_t(i)] = next_point++;
      const P2& p = loop.pieces[std::size_t(i)][0];
      os << "Point(" << junction[std::size_t(i)] << ") = {" << g17(p[0]) << ", " << g17(p[1]) << ", 0, h};\n";
    }
    for (int i = 0; i < n; ++i) {
      const Bezier& b = loop.pieces[std::size_t(i)];
      int ctrl[2];
      for (int k = 0; k < 2; ++k) {
        ctrl[k] = next_point++;
        os << "Point(" << ctrl[k] << ") = {" << g17(b[std::size_t(k + 1)][0]) << ", " << g17(b[std::size_t(k + 1)][1])
           << ", 0, h};\n";
      }
      const int c = next_curve++;
      os << "Bezier(" << c << ") = {" << junction[std::size_t(i)] << ", " << ctrl[0] << ", " << ctrl[1] << ", "
         << junction[std::size_t((i + 1) % n)] << "};\n";
      curves_of[std::size_t(l)].push_back(c);
    }
    os << "Curve Loop(" << l + 1 << ") = {";
    for (std::size_t k = 0; k < curves_of[std::size_t(l)].size(); ++k) os << (k ? ", " : "") << curves_of[std::size_t(l)][k];
    os << "};\n";
  }
  std::vector<int> surfaces;
  for (int l = 0; l < curve.n_loops(); ++l) {
    if (curve.is_hole(l)) continue;
    std::vector<int> loops{l + 1};
    for (int k = 0; k < curve.n_loops(); ++k)
      if (curve.is_hole(k) && curve.nesting_depth(k) == curve.nesting_depth(l) + 1 &&
          inside_loop(curve, l, curve.evaluate(k, 0.0)))
        loops.push_back(k + 1);
    const int s = int(surfaces.size()) + 1;
    surfaces.push_back(s);
    os << "Plane Surface(" << s << ") = {";
    for (std::size_t k = 0; k < loops.size(); ++k) os << (k ? ", " : "") << loops[k];
    os << "};\n";
  }
  os << "Physical Curve(\"interface\") = {1:" << next_curve - 1 << "};\n";
  os << "Physical Surface(\"solid\") = {1:" << surfaces.size() << "};\n";
  return os.str();
}

GmshRun run_gmsh(const std::string& gmsh, const std::string& geo, const fs::path& dir, const std::string& name) {
  GmshRun r;
  const fs::path geo_path = dir / (name + ".geo"), msh_path = dir / (name + ".msh"), log_path = dir / (name + ".log");
  {
    std::ofstream os(geo_path);
    os << geo;
    if (!os) throw InputError(geo_path.string() + ": cannot write");
  }
  fs::remove(msh_path);
  const std::vector<std::string> argv_s{gmsh, "-2", geo_path.string(), "-o", msh_path.string(), "-format", "msh41",
                                        "-nt", "1", "-v", "2"};
  std::vector<char*> argv;
  for (const auto& a : argv_s) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  const auto t0 = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, gmsh.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    r.error = "cannot run " + gmsh + ": " + std::strerror(rc);
    return r;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::string log;
  {
    std::ifstream in(log_path);
    std::stringstream ss;
    ss << in.rdbuf();
    log = ss.str();
  }
  const std::string errors = error_lines(log);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !errors.empty() || !fs::exists(msh_path)) {
    r.error = !errors.empty() ? errors
              : WIFEXITED(status) ? gmsh + " exited with status " + std::to_string(WEXITSTATUS(status)) + ": " + log
                                  : gmsh + " was killed by signal " + std::to_string(WTERMSIG(status));
    return r;
  }
  try {
    r.mesh = read_msh<2>(msh_path);
  } catch (const InputError& e) {
    r.error = std::string("cannot read Gmsh's mesh: ") + e.what();
    return r;
  }
  if (r.mesh.solid.empty()) {
    r.error = "Gmsh wrote no surface elements" + (log.empty() ? std::string() : ": " + log);
    return r;
  }
  r.ok = true;
  return r;
}

Comparison2d compare_with_gmsh(const CurveBoundary& curve, const Options2d& opt, const CompareOptions2d& copt,
                               const fs::path& out) {
  Comparison2d c;
  std::ostringstream settings;
  settings << "mesh2d level " << (opt.level == no_level ? curve.global_level() : opt.level) << ", "
           << name(opt.elements) << ", " << opt.smoothing_iterations << " smoothing iterations, " << opt.n_threads
           << " thread(s)";
  try {
    const auto t0 = std::chrono::steady_clock::now();
    const Result2d r = mesh2d(curve, opt);
    write_msh<2>(r.fe.mesh, out / "mesh.msh");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    c.febemesh = measure_mesh2d(r.fe.mesh, curve);
    c.febemesh.wall_seconds = seconds;
    c.febemesh.elements_per_second = double(c.febemesh.elements) / seconds;
  } catch (const std::exception& e) {
    c.febemesh.ok = false;
    c.febemesh.error = e.what();
  }
  c.febemesh.settings = settings.str();

  const Box<2> bb = curve.bounding_box();
  const double target = c.febemesh.ok ? double(c.febemesh.elements) : 0.0;
  double h = target > 0 ? initial_gmsh_size(curve.area(), target, opt.elements) : (bb.hi - bb.lo).norm() / 50.0;
  GmshRun best;
  for (int it = 0; it < std::max(1, copt.max_iterations); ++it) {
    GmshRun run = run_gmsh(copt.gmsh, gmsh_geo(curve, h, opt.elements), out, "gmsh");
    ++c.gmsh_iterations;
    c.gmsh_size = h;
    if (!run.ok) {
      best = std::move(run);
      break;
    }
    const double n = double(run.mesh.solid.size());
    c.gmsh_trials.emplace_back(h, run.mesh.solid.size());
    best = std::move(run);
    if (target <= 0 || std::abs(n - target) <= copt.tolerance * target) break;
    h *= std::sqrt(n / target);
  }
  std::ostringstream gs;
  gs << "gmsh -2 -nt 1 (Frontal-Delaunay default"
     << (opt.elements == ElementKind::Tri     ? ""
         : opt.elements == ElementKind::Mixed ? ", RecombineAll with Blossom: quad-dominant"
                                              : ", RecombineAll with Blossom and SubdivisionAlgorithm 1: all quads")
     << "), uniform size h = " << c.gmsh_size << " after " << c.gmsh_iterations << " run(s)";
  if (best.ok) {
    c.gmsh = measure_mesh2d(best.mesh, curve);
    c.gmsh.wall_seconds = best.wall_seconds;
    c.gmsh.elements_per_second = double(c.gmsh.elements) / best.wall_seconds;
  } else {
    c.gmsh.ok = false;
    c.gmsh.error = best.error;
  }
  c.gmsh.settings = gs.str();
  return c;
}

}  // namespace febemesh::dim2
