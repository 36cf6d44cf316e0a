#pragma once
// Geometric fidelity of a 2D mesh against the exact curve (DESIGN.md "Validity and quality"):
// area error, a Hausdorff estimate between the BE mesh and the curve, and how far the interface
// nodes are from the curve.

#include "dim2/curve_boundary.hpp"
#include "dim2/templates2d.hpp"

namespace febemesh::dim2 {

struct Fidelity2d {
  double exact_area = 0.0;        ///< of the B-spline domain (Green's theorem, exact)
  double fe_area = 0.0;           ///< sum of the FE element areas
  double be_polygon_area = 0.0;   ///< area enclosed by the BE polygons
  double area_rel_error = 0.0;    ///< |fe_area - exact_area| / exact_area
  double hausdorff = 0.0;         ///< max over BE edges of the curve's distance to the edge
  double hausdorff_rel = 0.0;     ///< hausdorff / diagonal of the curve's bounding box
  double max_node_distance = 0.0; ///< max distance of an interface node to the curve
  double max_node_distance_rel = 0.0;
};

/// Smallest corner angle (degrees) over the FE elements that lie away from every input corner
/// sharper than `sharp_deg` (the quality bar exempts those corners: no element there can beat
/// the corner's own angle). "Away" = farther than max(8, 2 / tan(angle / 2)) of the element's
/// own sizes: 8 sizes, or the part of the corner's wedge thinner than 4 element sizes. Also
/// returns how many elements were exempt through `n_exempt`. On n_threads threads (the same
/// numbers for every count).
double min_angle_away_from_sharp_corners(const Mesh<2>& m, const CurveBoundary& curve, double sharp_deg,
                                         std::size_t* n_exempt = nullptr, int n_threads = 1);

/// Corner angles (degrees) over the elements away from sharp corners, as above, by kind: the
/// triangles' smallest angle and the quads' smallest and largest (the bars are >= 20 deg for
/// triangles and [30, 150] deg for quads). 180 / 0 when there is no such element.
struct AnglesAwayFromCorners {
  double min_triangle_deg = 180.0;
  double min_quad_deg = 180.0;
  double max_quad_deg = 0.0;
  std::size_t n_exempt = 0;
};
AnglesAwayFromCorners angles_away_from_sharp_corners(const Mesh<2>& m, const CurveBoundary& curve, double sharp_deg,
                                                     int n_threads = 1);

/// `samples` curve points per BE edge for the Hausdorff estimate (one-sided from the curve,
/// which dominates: the BE edges are chords of the curve).
Fidelity2d measure_fidelity(const FeBeMesh& m, const CurveBoundary& curve, int samples = 16);

}  // namespace febemesh::dim2
