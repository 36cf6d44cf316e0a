#pragma once
// febemesh against TetGen on the same closed surface (issue 7, `febemesh compare3d`).
//
// Both tools run the same way: in a forked child process, from the surface file to a written
// .msh (ours: SurfaceBoundary::from_file, mesh3d, write_msh; TetGen: read_surface, libtet's
// tetrahedralize with "pq1.414/10a<vol>Q", write_msh). The child reports its wall time and its
// peak-RSS growth (VmHWM after the run minus VmRSS at the start, with the high-water mark
// reset through /proc/self/clear_refs), so neither tool's memory hides in the other's. The
// parent reads both .msh files back and measures them with the same code (measure_mesh3d).
// TetGen's volume bound is rescaled until its tet count is within a tolerance of ours.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/surface.hpp"
#include "dim3/surface_boundary.hpp"

namespace febemesh::dim3 {

struct MeshMetrics3d {
  bool ok = false;
  std::string error;          ///< the tool's failure message, verbatim, when !ok
  std::string settings;
  std::size_t elements = 0;   ///< tetrahedra
  std::size_t nodes = 0;
  std::size_t boundary_triangles = 0;
  double wall_seconds = 0.0;
  double elements_per_second = 0.0;
  long peak_memory_bytes = 0;
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  std::size_t slivers_below_10deg = 0;
  double min_scaled_jacobian = 0.0;
  double mean_scaled_jacobian = 0.0;
  double max_radius_ratio = 0.0;
  double volume_rel_error = 0.0;
  double hausdorff_rel = 0.0;
  std::vector<double> element_min_dihedral_deg;  ///< per element, for histograms
  std::vector<double> element_max_dihedral_deg;
  std::vector<double> element_radius_ratio;
  std::vector<double> element_scaled_jacobian;
};

/// Measures `mesh` (solid = tets, interface = boundary triangles) against the surface.
MeshMetrics3d measure_mesh3d(const Mesh<3>& mesh, const SurfaceBoundary& surface);

/// What a job run in a child process reports.
struct ChildResult {
  bool ok = false;
  std::string error;
  double wall_seconds = 0.0;
  long peak_memory_growth_bytes = 0;
};

/// Runs `job` in a forked child. An exception's what() (or a crash) becomes the error.
ChildResult run_in_child(const std::function<void()>& job);

/// Error thrown by tetgen_mesh when libtet gives up: its code, its meaning and what it printed.
class TetgenError : public std::runtime_error {
 public:
  TetgenError(int code, const std::string& message) : std::runtime_error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

/// The meaning of TetGen's exit codes (terminatetetgen in tetgen.h).
std::string tetgen_code_meaning(int code);

/// Tetrahedralizes the closed surface `soup` with TetGen `switches` (e.g. "pq1.414/10a0.01Q").
/// Solid = tets (positively oriented), interface = TetGen's boundary faces.
/// Throws TetgenError with TetGen's code and printed output. What TetGen prints goes to
/// `log_path` as it prints it, when given. Caution: libtet 1.5 can crash (SIGSEGV in its
/// memory pools' cleanup) while failing, e.g. on a self-intersecting surface, so compare3d runs
/// it in a child process (run_in_child) with a log.
Mesh<3> tetgen_mesh(const TriangleSoup& soup, const std::string& switches, const std::string& log_path = "");

struct CompareOptions3d {
  double tolerance = 0.2;
  int max_iterations = 6;
  std::string quality = "1.414/10";  ///< TetGen's -q radius-edge / dihedral bounds
};

struct Comparison3d {
  MeshMetrics3d febemesh;
  MeshMetrics3d tetgen;
  std::string tetgen_switches;
  std::vector<std::pair<double, std::size_t>> tetgen_trials;  ///< (volume bound, tets) per run
};

/// Meshes `surface_path` with mesh3d into out/mesh.msh and with TetGen into out/tetgen.msh.
/// Our failure (mesh3d throws) is reported in febemesh.error; TetGen then runs without a
/// volume bound. Throws InputError when the surface itself cannot be read.
Comparison3d compare_with_tetgen(const std::string& surface_path, const Options3d& opt,
                                 const CompareOptions3d& copt, const std::filesystem::path& out);

}  // namespace febemesh::dim3
