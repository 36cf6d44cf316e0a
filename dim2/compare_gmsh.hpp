#pragma once
// febemesh against Gmsh on the same exact curves (issue 7, `febemesh compare2d`).
//
// Gmsh gets a .geo with one `Bezier{}` curve per cubic piece of our loops (the exact geometry,
// not a polyline), a `Curve Loop` per loop and a `Plane Surface` per outer loop with the holes
// directly inside it. Its mesh size is chosen so that its triangle count lands within a
// tolerance of ours (a uniform size h gives about 4 A / (sqrt(3) h^2) triangles; h is rescaled
// by sqrt(count ratio) a few times). Quad and mixed meshes use Gmsh's recombination. Both meshes are then measured by the same code
// (measure_mesh2d): quality from core/quality.hpp, area against CurveBoundary::area(), and a
// two-sided Hausdorff estimate between the curve and the boundary polyline.
// Wall times: ours is mesh2d plus writing mesh.msh, in process; Gmsh's is its whole
// subprocess (reading the .geo, meshing, writing the .msh). Both single-threaded.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::dim2 {

/// What the comparison reports per tool; the same code fills it for both.
struct MeshMetrics2d {
  bool ok = false;
  std::string error;             ///< the tool's failure message, verbatim, when !ok
  std::string settings;          ///< how the tool was run (options, mesh size)
  std::size_t elements = 0;      ///< FE elements (triangles / quads)
  std::size_t quads = 0;         ///< of which quadrilaterals
  std::size_t nodes = 0;
  std::size_t boundary_edges = 0;
  double wall_seconds = 0.0;
  double elements_per_second = 0.0;
  double min_angle_deg = 0.0;
  double max_angle_deg = 0.0;
  double min_scaled_jacobian = 0.0;
  double mean_scaled_jacobian = 0.0;
  std::size_t below_30deg = 0;   ///< elements whose smallest angle is below 30 degrees
  double area_rel_error = 0.0;   ///< |mesh area - exact area| / exact area
  double hausdorff_rel = 0.0;    ///< max(curve -> boundary edges, boundary edges -> curve) / bbox diagonal
  double node_distance_rel = 0.0;///< max distance of a boundary node to the curve / bbox diagonal
  std::vector<double> element_min_angle_deg;  ///< per element, for histograms
  std::vector<double> element_scaled_jacobian;
};

/// Measures `mesh` (solid = FE elements, interface = boundary edges) against the exact curve.
/// `wall_seconds` is left to the caller.
MeshMetrics2d measure_mesh2d(const Mesh<2>& mesh, const CurveBoundary& curve);

/// Two-sided Hausdorff estimate between the curve and the polyline of `edges` (Line2 elements):
/// dense curve samples (spacing a fraction of the typical edge) to their nearest edge, and
/// samples of every edge to the curve.
double curve_polyline_hausdorff(const CurveBoundary& curve, const std::vector<Point<2>>& points,
                                const Elements& edges);

/// Gmsh .geo text of the domain with mesh size `h` everywhere; exact cubic Bezier pieces.
/// Physical groups "solid" (surfaces) and "interface" (curves), as core/read_msh expects.
/// quad / mixed add Gmsh's recombination (gmsh_recombination).
std::string gmsh_geo(const CurveBoundary& curve, double h, ElementKind kind = ElementKind::Tri);

/// The .geo options that make Gmsh produce our element kind: nothing for tri; mixed:
/// Mesh.RecombineAll with the Blossom algorithm (quad-dominant, triangles left where pairing
/// fails); quad: the same, then Mesh.SubdivisionAlgorithm = 1 (every element split into quads,
/// as our quad mode splits the mixed mesh once more).
std::string gmsh_recombination(ElementKind kind);

/// Gmsh's uniform mesh size expected to give `target` elements of `kind` on `area`.
double initial_gmsh_size(double area, double target, ElementKind kind);

struct GmshRun {
  bool ok = false;
  std::string error;   ///< Gmsh's error lines (or the exec failure), verbatim
  double wall_seconds = 0.0;
  Mesh<2> mesh;
};

/// Writes `geo` to dir/name.geo, runs `gmsh -2 -nt 1` on it into dir/name.msh (log in
/// dir/name.log) and reads the mesh back. Never throws for Gmsh's failures (they go in error).
GmshRun run_gmsh(const std::string& gmsh, const std::string& geo, const std::filesystem::path& dir,
                 const std::string& name);

struct CompareOptions2d {
  std::string gmsh = "gmsh";    ///< program to run
  double tolerance = 0.2;       ///< accepted relative difference of element counts
  int max_iterations = 6;       ///< mesh-size rescalings
};

struct Comparison2d {
  MeshMetrics2d febemesh;
  MeshMetrics2d gmsh;
  double gmsh_size = 0.0;       ///< the final Gmsh mesh size
  int gmsh_iterations = 0;
  std::vector<std::pair<double, std::size_t>> gmsh_trials;  ///< (size, element count) per run
};

/// Runs mesh2d (our mesh written to out/mesh.msh) and then Gmsh in `out`, with the same element
/// kind (opt.elements), until the counts match. Our failure (an exception of mesh2d) is reported in febemesh.error; Gmsh then runs
/// once with size = bounding-box diagonal / 50.
Comparison2d compare_with_gmsh(const CurveBoundary& curve, const Options2d& opt, const CompareOptions2d& copt,
                               const std::filesystem::path& out);

}  // namespace febemesh::dim2
