#include "dim2/fidelity2d.hpp"

#include <algorithm>
#include <cmath>

#include "core/distance.hpp"
#include "core/quality.hpp"
#include "dim2/improve2d.hpp"
#include "dim2/loop_geometry.hpp"

namespace febemesh::dim2 {

double min_angle_away_from_sharp_corners(const Mesh<2>& m, const CurveBoundary& curve, double sharp_deg,
                                         std::size_t* n_exempt) {
  std::vector<P2> sharp;
  for (const CurveCorner& c : curve.corners())
    if (c.angle_deg < sharp_deg) sharp.push_back(c.point);
  double best = 180.0;
  std::size_t exempt = 0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const int n = m.solid.n_nodes_of(id);
    const VertexId* v = m.solid.nodes(id);
    double size = 0.0;
    for (int k = 0; k < n; ++k) size = std::max(size, (m.points[v[k].v] - m.points[v[(k + 1) % n].v]).norm());
    bool near = false;
    for (const P2& c : sharp)
      for (int k = 0; k < n && !near; ++k) near = (m.points[v[k].v] - c).norm() <= 8.0 * size;
    if (near) {
      ++exempt;
      continue;
    }
    best = std::min(best, min_corner_angle_deg(m, e));
  }
  if (n_exempt) *n_exempt = exempt;
  return best;
}

Fidelity2d measure_fidelity(const FeBeMesh& m, const CurveBoundary& curve, int samples) {
  Fidelity2d f;
  f.exact_area = curve.area();
  f.fe_area = solid_measure<2>(m.mesh);
  f.be_polygon_area = interface_enclosed_measure<2>(m.mesh);
  f.area_rel_error = std::abs(f.fe_area - f.exact_area) / f.exact_area;
  const Box<2> bb = curve.bounding_box();
  const double diag = (bb.hi - bb.lo).norm();
  for (std::size_t e = 0; e < m.mesh.interface.size(); ++e) {
    const VertexId* v = m.mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    const BoundaryLocation &wa = m.where[v[0].v], &wb = m.where[v[1].v];
    const P2 &a = m.mesh.points[v[0].v], &b = m.mesh.points[v[1].v];
    if (wa.patch < 0 || wa.patch != wb.patch) {
      f.hausdorff = std::numeric_limits<double>::infinity();
      continue;
    }
    const Loop& loop = curve.loops()[wa.patch];
    const double n = static_cast<double>(loop.n_pieces());
    double d = std::fmod(wb.param[0] - wa.param[0], n);
    if (d < 0) d += n;
    for (int s = 1; s < samples; ++s) {
      const P2 p = evaluate(loop, wrap_parameter(loop, wa.param[0] + d * s / samples));
      f.hausdorff = std::max(f.hausdorff, point_segment_distance<2>(p, a, b));
    }
  }
  for (std::size_t v = 0; v < m.where.size(); ++v) {
    if (m.where[v].patch < 0) continue;
    f.max_node_distance = std::max(f.max_node_distance, curve.closest_point(m.mesh.points[v]).distance);
  }
  f.hausdorff_rel = f.hausdorff / diag;
  f.max_node_distance_rel = f.max_node_distance / diag;
  return f;
}

}  // namespace febemesh::dim2
