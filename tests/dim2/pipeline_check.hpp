#pragma once
// Shared by the property suite and the real-data regression: run the whole 2D pipeline on a
// domain and measure what DESIGN.md "Validity and quality" asks (core validator, fidelity to
// the curve, element quality), the way tests/dim2/test_pipeline2d.cpp does.

#include <algorithm>
#include <string>
#include <vector>

#include "core/quality.hpp"
#include "core/validate.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/fidelity2d.hpp"
#include "dim2/pipeline2d.hpp"

namespace febemesh::test {

struct PipelineOutcome {
  dim2::Result2d r;
  ValidationReport v;
  dim2::Fidelity2d f;
  QualitySummary q;
  /// Corners of the curve that are no interface node of the mesh (bit-exact position).
  std::size_t corners_off_mesh = 0;
};

/// Meshes `curve` (after set_global_level(opt.level) when opt.level is given) and checks the
/// output: Euler = components - holes, interface nodes within 1e-10 of the bounding-box diagonal,
/// the curve's corners that are not interface nodes.
inline PipelineOutcome run_pipeline(dim2::CurveBoundary& curve, const dim2::Options2d& opt) {
  if (opt.level != dim2::no_level) curve.set_global_level(opt.level);
  PipelineOutcome out{dim2::mesh2d(curve, opt), {}, {}, {}};
  ValidateOptions<2> vo;
  vo.expected_euler = curve.n_components() - curve.n_holes();
  const Box<2> bb = curve.bounding_box();
  vo.boundary_distance = [&](const Point<2>& p) { return curve.closest_point(p).distance; };
  vo.boundary_tolerance = 1e-10 * (bb.hi - bb.lo).norm();
  out.v = validate<2>(out.r.fe.mesh, vo);
  out.f = dim2::measure_fidelity(out.r.fe, curve);
  out.q = summarize_quality<2>(out.r.fe.mesh);
  std::vector<Point<2>> on_interface;
  for (const VertexId v : out.r.fe.mesh.interface.node) on_interface.push_back(out.r.fe.mesh.points[v.v]);
  auto lex = [](const Point<2>& a, const Point<2>& b) { return a[0] < b[0] || (a[0] == b[0] && a[1] < b[1]); };
  std::sort(on_interface.begin(), on_interface.end(), lex);
  for (const dim2::CurveCorner& c : curve.corners())
    out.corners_off_mesh += !std::binary_search(on_interface.begin(), on_interface.end(), c.point, lex);
  return out;
}

}  // namespace febemesh::test
