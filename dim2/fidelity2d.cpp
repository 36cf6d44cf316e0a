#include "dim2/fidelity2d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/distance.hpp"
#include "core/parallel_ranges.hpp"
#include "core/quality.hpp"
#include "dim2/improve2d.hpp"
#include "dim2/loop_geometry.hpp"

namespace febemesh::dim2 {

// Cost: atan2 at every corner was most of this (and of report.json). The extreme angles are
// those of the extreme corner cotangents (dot / cross: the angle falls as it rises), so a first
// pass finds the extreme cotangents and only the elements within rounding of them (1e-9 of
// 1 + c^2, far beyond the ~1e-15 at which a quotient and atan2 can disagree on the order) get
// their corners' angles; the bounds are the same numbers as from every element's.
AnglesAwayFromCorners angles_away_from_sharp_corners(const Mesh<2>& m, const CurveBoundary& curve,
                                                     double sharp_deg, int n_threads) {
  // Exempt radius in element sizes: 8, or the distance from the tip at which the corner's
  // wedge is 4 element sizes wide (w = 2 r tan(a/2)), whichever is larger; inside it the
  // wedge, not the mesher, sets the angles.
  std::vector<std::pair<P2, double>> sharp;
  for (const CurveCorner& c : curve.corners())
    if (c.angle_deg < sharp_deg)
      sharp.emplace_back(c.point, std::max(8.0, 2.0 / std::tan(0.5 * std::max(c.angle_deg, 1e-3) * M_PI / 180.0)));
  AnglesAwayFromCorners out;
  auto exempt = [&](const VertexId* v, int n) {
    if (sharp.empty()) return false;
    double size = 0.0;
    for (int k = 0; k < n; ++k) size = std::max(size, (m.points[v[k].v] - m.points[v[(k + 1) % n].v]).norm());
    bool near = false;
    for (const auto& [c, radius] : sharp)
      for (int k = 0; k < n && !near; ++k) near = (m.points[v[k].v] - c).norm() <= radius * size;
    return near;
  };
  // Largest and smallest corner cotangent of an element; +inf / -inf when a corner is reflex
  // or inverted (it counts as 0 deg for the smallest angle and 180 for the largest).
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto cot_range = [&](const VertexId* v, int n) {
    std::pair<double, double> r{-inf, inf};
    for (int k = 0; k < n; ++k) {
      const P2 a = m.points[v[(k + n - 1) % n].v] - m.points[v[k].v], b = m.points[v[(k + 1) % n].v] - m.points[v[k].v];
      const double cr = b[0] * a[1] - b[1] * a[0];
      if (!(cr > 0)) return std::pair{inf, -inf};
      const double c = a.dot(b) / cr;
      if (!std::isfinite(c)) return std::pair{inf, -inf};  // not ordered by cotangent: always measured
      r.first = std::max(r.first, c);
      r.second = std::min(r.second, c);
    }
    return r;
  };
  // Both passes in fixed chunks on n_threads threads, each with its own extremes and count
  // (maxima, minima and integer counts: the same numbers for every thread count).
  const std::size_t n_elems = m.solid.size();
  const std::size_t chunk = chunk_size(n_elems, n_threads, std::size_t(1) << 14);
  const std::size_t n_chunks = (n_elems + chunk - 1) / chunk;
  struct Part {
    double top_tri = -inf, top_quad = -inf, bottom_quad = inf;  // over finite cotangents
    AnglesAwayFromCorners a;
  };
  std::vector<Part> parts(n_chunks);
  std::vector<std::uint8_t> away(n_elems, 0);
  for_each_chunk(n_elems, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    Part& p = parts[c];
    for (std::size_t e = begin; e < end; ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = m.solid.n_nodes_of(id);
      const VertexId* v = m.solid.nodes(id);
      if (exempt(v, n)) {
        ++p.a.n_exempt;
        continue;
      }
      away[e] = 1;
      const auto [top, bottom] = cot_range(v, n);
      if (!std::isfinite(top)) continue;
      if (n == 3) {
        p.top_tri = std::max(p.top_tri, top);
      } else {
        p.top_quad = std::max(p.top_quad, top);
        p.bottom_quad = std::min(p.bottom_quad, bottom);
      }
    }
  });
  double top_tri = -inf, top_quad = -inf, bottom_quad = inf;
  for (const Part& p : parts) {
    top_tri = std::max(top_tri, p.top_tri), top_quad = std::max(top_quad, p.top_quad);
    bottom_quad = std::min(bottom_quad, p.bottom_quad);
    out.n_exempt += p.a.n_exempt;
  }
  auto within = [](double c, double extreme) { return std::abs(c - extreme) <= 1e-9 * (1.0 + extreme * extreme); };
  for_each_chunk(n_elems, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    AnglesAwayFromCorners& a = parts[c].a;
    for (std::size_t e = begin; e < end; ++e) {
      if (!away[e]) continue;
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = m.solid.n_nodes_of(id);
      const VertexId* v = m.solid.nodes(id);
      const auto [top, bottom] = cot_range(v, n);
      const bool measured = !std::isfinite(top) ||
                            (n == 3 ? within(top, top_tri) : within(top, top_quad) || within(bottom, bottom_quad));
      if (!measured) continue;
      double lo = 180.0, hi = 0.0;
      for (int k = 0; k < n; ++k) {
        const P2 pa = m.points[v[(k + n - 1) % n].v] - m.points[v[k].v], pb = m.points[v[(k + 1) % n].v] - m.points[v[k].v];
        const double cr = pb[0] * pa[1] - pb[1] * pa[0];
        // A reflex or inverted corner counts as 0 deg (the worst) for both bounds.
        const double ang = cr > 0 ? std::atan2(cr, pa.dot(pb)) * 180.0 / M_PI : 0.0;
        lo = std::min(lo, ang);
        hi = std::max(hi, cr > 0 ? ang : 180.0);
      }
      if (n == 3) {
        a.min_triangle_deg = std::min(a.min_triangle_deg, lo);
      } else {
        a.min_quad_deg = std::min(a.min_quad_deg, lo);
        a.max_quad_deg = std::max(a.max_quad_deg, hi);
      }
    }
  });
  for (const Part& p : parts) {
    out.min_triangle_deg = std::min(out.min_triangle_deg, p.a.min_triangle_deg);
    out.min_quad_deg = std::min(out.min_quad_deg, p.a.min_quad_deg);
    out.max_quad_deg = std::max(out.max_quad_deg, p.a.max_quad_deg);
  }
  return out;
}

double min_angle_away_from_sharp_corners(const Mesh<2>& m, const CurveBoundary& curve, double sharp_deg,
                                         std::size_t* n_exempt, int n_threads) {
  const AnglesAwayFromCorners a = angles_away_from_sharp_corners(m, curve, sharp_deg, n_threads);
  if (n_exempt) *n_exempt = a.n_exempt;
  return std::min(a.min_triangle_deg, a.min_quad_deg);
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
  for (const std::int32_t v : m.where.nodes())
    f.max_node_distance = std::max(f.max_node_distance, curve.closest_point(m.mesh.points[v]).distance);
  f.hausdorff_rel = f.hausdorff / diag;
  f.max_node_distance_rel = f.max_node_distance / diag;
  return f;
}

}  // namespace febemesh::dim2
