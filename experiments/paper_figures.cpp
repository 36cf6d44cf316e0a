// Experiment: the paper's Figures 1-12, redrawn by febemesh (issue 7, `paper_figures`).
//
// The paper illustrates its algorithm on two mechanical parts: a part "in interaction with the
// fluid around it" (Figure 1) and a second example (Figure 2) that Figures 3-12 then follow
// through every stage. We do the same for our two paper-like examples, the angle bracket
// (examples/bracket.json) and the pipe flange (examples/flange.json), at the level their files
// ask for, and write one SVG per figure:
//
//   Fig. 1/2   control points (simple, corner = tripled knot, interior) and the B-spline curve,
//              with the B-spline control polygon recovered from the Bezier pieces;
//   Fig. 2a    the mesh control parameters: the level field control_level() over the root
//              square, with the interior control points and their radii;
//   Fig. 3     quadrants after check_and_subdivide_quadrant;      (dim2/figures2d)
//   Fig. 4     after the one-level-difference rule;                 (dim2/figures2d)
//   Fig. 5     interior quadrants;                                  (dim2/figures2d)
//   Fig. 6     one boundary quadrant close up: free edge L = Q1Q2 of interior quadrant "1",
//              projections P1, P2 on the curve (eq. 1), the projection segments;
//   Fig. 7     interior and boundary quadrants before corner pulling; (dim2/figures2d)
//   Fig. 8     after pulling to corners;                            (dim2/figures2d)
//   Fig. 9     after Laplacian smoothing;                           (dim2/figures2d)
//   Fig. 10    the boundary quadrants alone;
//   Fig. 11    the boundary elements;                               (dim2/figures2d)
//   Fig. 12    the finite element mesh;                             (dim2/figures2d)
//   Fig. 12a   the templates: the six hanging-node configurations of a balanced quadrant and
//              the two boundary quadrant shapes, for tri, mixed and quad meshes.
//
// The stage figures come from dim2::write_stage_figures (the same ones `mesh2d` writes); the
// figures the pipeline does not draw are drawn here with core/svg_canvas.
//
// Output: results/paper_figures/<example>/figNN-*.svg and index.md (captions with counts), and
// results/paper_figures/index.md linking both. Usage: paper_figures [OUTDIR] [INPUT.json ...]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "core/svg_canvas.hpp"
#include "core/validate.hpp"
#include "dim2/curve_boundary.hpp"
#include "dim2/figures2d.hpp"
#include "dim2/loop_geometry.hpp"
#include "dim2/pipeline2d.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/templates2d.hpp"

using namespace febemesh;
using namespace febemesh::dim2;
namespace fs = std::filesystem;

namespace {

const std::string ink = "#222222";
const std::string curve_blue = "#1f5fbf";
const std::string interior_fill = "#dbe9f7";
const std::string boundary_fill = "#f7d9a8";
const std::string corner_red = "#c0392b";
const std::string control_green = "#1e8449";

/// A figure as index.md lists it.
struct Figure {
  std::string number;  ///< "1", "2a", "12a"
  std::string file;
  std::string caption;
};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::vector<P2> sample_loop(const CurveBoundary& curve, int loop, int per_piece) {
  std::vector<P2> pts;
  const int n = int(curve.loops()[std::size_t(loop)].n_pieces());
  for (int i = 0; i < n; ++i)
    for (int s = 0; s < per_piece; ++s) pts.push_back(curve.evaluate(loop, i + double(s) / per_piece));
  pts.push_back(pts.front());
  return pts;
}

void draw_curve(SvgCanvas& c, const CurveBoundary& curve, double width, int per_piece = 16) {
  for (int l = 0; l < curve.n_loops(); ++l) c.polyline(sample_loop(curve, l, per_piece), {"none", curve_blue, width, 1.0});
}

/// The control polygon of the closed uniform cubic B-spline behind a loop. A piece i of such a
/// loop has inner Bezier points b1 = (2 q_i + q_{i+1}) / 3 and b2 = (q_i + 2 q_{i+1}) / 3, so
/// q_i = 2 b1 - b2 (dim2/curve_model.hpp, loop_from_bspline). The result is checked against
/// de Boor's algorithm (bspline_point_ref); a loop that is not a uniform B-spline (an SVG path)
/// gives an empty polygon.
std::vector<P2> recover_control_polygon(const Loop& loop) {
  std::vector<P2> q;
  for (const Bezier& b : loop.pieces) q.push_back(2.0 * b[1] - b[2]);
  double scale = 0.0;
  for (const Bezier& b : loop.pieces) scale = std::max(scale, b[0].norm());
  for (std::size_t i = 0; i < loop.pieces.size(); ++i)
    for (double u : {0.0, 0.3, 0.7}) {
      const P2 expected = evaluate(loop, double(i) + u);
      if ((bspline_point_ref(q, double(i) + u) - expected).norm() > 1e-9 * std::max(1.0, scale)) return {};
    }
  return q;
}

/// Control points of the input: consecutive equal points of the control polygon collapse into
/// one; a point repeated three times is a corner (the paper's tripled knot).
struct InputPoint {
  P2 p;
  int multiplicity;
};
std::vector<InputPoint> collapse(const std::vector<P2>& q) {
  std::vector<InputPoint> out;
  for (const P2& p : q) {
    if (!out.empty() && (out.back().p - p).norm() < 1e-12) {
      ++out.back().multiplicity;
      continue;
    }
    out.push_back({p, 1});
  }
  if (out.size() > 1 && (out.front().p - out.back().p).norm() < 1e-12) {
    out.front().multiplicity += out.back().multiplicity;
    out.pop_back();
  }
  return out;
}

void draw_interior_controls(SvgCanvas& c, const CurveBoundary& curve) {
  for (const InteriorControl& ic : curve.domain().interior) {
    if (ic.radius > 0) c.circle(ic.p, ic.radius, {"none", control_green, 1.2, 1.0});
    c.dot(ic.p, 4.0, {control_green, "none", 0.0, 1.0});
    c.text(ic.p + P2(0.02, 0.02) * (curve.root_box().hi[0] - curve.root_box().lo[0]),
           "level " + fmt("%g", ic.level), 12.0, control_green);
  }
}

/// Figures 1 and 2: control points and the B-spline representation of the boundary.
Figure control_points_figure(const CurveBoundary& curve, const fs::path& dir, const std::string& number) {
  SvgCanvas c;
  c.set_view(curve.root_box());
  std::size_t n_simple = 0, n_corner = 0;
  bool all_bspline = true;
  for (const Loop& loop : curve.loops()) {
    std::vector<P2> q = recover_control_polygon(loop);
    if (q.empty()) {
      all_bspline = false;
      continue;
    }
    q.push_back(q.front());
    c.polyline(q, {"none", "#9a9a9a", 0.7, 1.0});
  }
  draw_curve(c, curve, 2.0);
  for (const Loop& loop : curve.loops()) {
    const std::vector<P2> q = recover_control_polygon(loop);
    for (const InputPoint& ip : collapse(q)) {
      if (ip.multiplicity >= 3) {
        ++n_corner;
        const double r = 0.006 * (curve.root_box().hi[0] - curve.root_box().lo[0]);
        c.polygon({ip.p + P2(-r, -r), ip.p + P2(r, -r), ip.p + P2(r, r), ip.p + P2(-r, r)}, {corner_red, "none", 0.0, 1.0});
      } else {
        ++n_simple;
        c.dot(ip.p, 2.5, {ink, "none", 0.0, 1.0});
      }
    }
  }
  draw_interior_controls(c, curve);
  c.text(P2(curve.root_box().lo[0], curve.root_box().hi[1]),
         "Fig. " + number + ": control points (black: simple, red: corner), control polygon (grey), B-spline (blue)",
         13.0, ink);
  const std::string file = "fig" + std::string(number.size() == 1 ? "0" : "") + number + "-control-points.svg";
  c.write(dir / file);
  std::ostringstream cap;
  cap << "Control points and B-spline representation of the boundary: " << curve.n_loops() << " closed loops ("
      << curve.n_holes() << " holes), " << n_simple << " simple points (type I), " << n_corner
      << " corner points (type II, tripled knots), " << curve.domain().interior.size()
      << " interior control points (type III, green, with their radius of influence); the grey polygon is the "
         "closed uniform B-spline's control polygon (corners appear three times)";
  if (!all_bspline) cap << "; some loops are not uniform B-splines and show no control polygon";
  cap << ".";
  return {number, file, cap.str()};
}

/// Figure 2a: the mesh control parameter field (the level the subdivision aims at) over a
/// 64 x 64 grid of the root square, as the subdivision rule reads it (control_level of a box).
Figure control_parameter_figure(const CurveBoundary& curve, const fs::path& dir) {
  SvgCanvas c;
  const Box<2> root = curve.root_box();
  c.set_view(root);
  const int n = 64;
  const double side = (root.hi[0] - root.lo[0]) / n;
  std::map<double, std::size_t> histogram;
  double lo = 1e9, hi = -1e9;
  std::vector<double> level(std::size_t(n * n));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const P2 a = root.lo + P2(i * side, j * side);
      const double v = curve.control_level(Box<2>{a, a + P2(side, side)});
      level[std::size_t(j * n + i)] = v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      ++histogram[v];
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double v = level[std::size_t(j * n + i)];
      const double s = hi > lo ? (v - lo) / (hi - lo) : 0.0;
      const P2 a = root.lo + P2(i * side, j * side);
      c.polygon({a, a + P2(side, 0), a + P2(side, side), a + P2(0, side)},
                {svg_rgb(1.0 - 0.8 * s, 1.0 - 0.55 * s, 1.0 - 0.2 * s), "none", 0.0, 1.0});
    }
  draw_curve(c, curve, 1.5);
  draw_interior_controls(c, curve);
  c.text(P2(root.lo[0], root.hi[1]),
         "Fig. 2a: mesh control parameter (target level) per box of root/64: white " + fmt("%g", lo) + ", dark " +
             fmt("%g", hi),
         13.0, ink);
  const std::string file = "fig02a-control-parameters.svg";
  c.write(dir / file);
  std::ostringstream cap;
  cap << "Mesh control parameters as the subdivision reads them: control_level() of each box of a 64 x 64 grid "
         "over the root square (white = level "
      << lo << ", darkest = level " << hi << "). Boxes per level:";
  for (const auto& [v, count] : histogram) cap << " " << v << ": " << count << ";";
  cap << " the curve carries the file's level, interior control points (green) raise it within their radius.";
  return {"2a", file, cap.str()};
}

/// The boundary quadrant shown in Figure 6: a typical one, four-sided, on a curved part away
/// from corners (the chord P1 P2 visibly off the curve), whose projection segments are closest to perpendicular to the free edge.
std::size_t pick_boundary_quadrant(const QuadrantComplex& qc, const CurveBoundary& curve) {
  std::size_t best = 0;
  double best_score = 1e300;
  for (std::size_t i = 0; i < qc.boundary.size(); ++i) {
    const BoundaryQuadrant& b = qc.boundary[i];
    if (b.is_triangle() || b.corner >= 0) continue;
    const P2 q2 = qc.points[std::size_t(b.node[0])], q1 = qc.points[std::size_t(b.node[1])];
    const P2 p1 = qc.points[std::size_t(b.node[2])], p2 = qc.points[std::size_t(b.node[3])];
    const BoundaryLocation& w = qc.where(b.node[2]);
    if (w.kind != BoundaryLocation::Kind::Smooth || w.patch < 0) continue;
    const P2 edge = (q2 - q1).normalized();
    const double score = std::abs((p1 - q1).normalized().dot(edge)) + std::abs((p2 - q2).normalized().dot(edge)) +
                         (curve.closest_point(0.5 * (p1 + p2)).distance > 0.005 * (p2 - p1).norm() ? 0.0 : 1.0);
    if (score < best_score) best_score = score, best = i;
  }
  return best;
}

bool touches(const Box<2>& view, const std::vector<P2>& poly) {
  Box<2> b = Box<2>::empty();
  for (const P2& p : poly) b.expand(p);
  return (b.lo.array() <= view.hi.array()).all() && (view.lo.array() <= b.hi.array()).all();
}

std::vector<P2> ring_points(const QuadrantComplex& qc, std::span<const std::int32_t> ids) {
  std::vector<P2> out;
  for (std::int32_t i : ids) out.push_back(qc.points[std::size_t(i)]);
  return out;
}

/// Figure 6: one boundary quadrant between a free edge of an interior quadrant and the curve.
Figure boundary_quadrant_figure(const CurveBoundary& curve, const QuadrantComplex& qc, const fs::path& dir) {
  SvgCanvas c(600.0, 20.0);
  const BoundaryQuadrant& b = qc.boundary[pick_boundary_quadrant(qc, curve)];
  const P2 q2 = qc.points[std::size_t(b.node[0])], q1 = qc.points[std::size_t(b.node[1])];
  const P2 p1 = qc.points[std::size_t(b.node[2])], p2 = qc.points[std::size_t(b.node[3])];
  Box<2> view = Box<2>::empty();
  for (const P2& p : {q1, q2, p1, p2}) view.expand(p);
  const P2 centre = 0.5 * (view.lo + view.hi);
  const double half = 1.6 * std::max(view.hi[0] - view.lo[0], view.hi[1] - view.lo[1]);
  view = Box<2>{centre - P2(half, half), centre + P2(half, half)};
  c.set_view(view);
  for (const InteriorQuadrant& q : qc.interior) {
    const auto poly = ring_points(qc, q.ring);
    if (!touches(view, poly)) continue;
    c.polygon(poly, {interior_fill, ink, 0.8, 1.0});
    if (q.leaf == b.leaf) {
      P2 m = P2::Zero();
      for (const P2& p : poly) m += p;
      c.text(m / double(poly.size()), "1", 22.0, ink);
    }
  }
  for (const BoundaryQuadrant& o : qc.boundary) {
    const auto poly = ring_points(qc, o.polygon());
    if (&o == &b || !touches(view, poly)) continue;
    c.polygon(poly, {"#fbeedb", "#b0b0b0", 0.6, 1.0});
  }
  c.polygon({q2, q1, p1, p2}, {boundary_fill, ink, 1.5, 1.0});
  draw_curve(c, curve, 2.0, 96);
  c.line(q1, p1, {"none", corner_red, 2.0, 1.0});
  c.line(q2, p2, {"none", corner_red, 2.0, 1.0});
  c.line(q1, q2, {"none", ink, 3.0, 1.0});
  const double off = 0.04 * half;
  for (const auto& [p, label] : std::vector<std::pair<P2, std::string>>{{q1, "Q1"}, {q2, "Q2"}, {p1, "P1"}, {p2, "P2"}}) {
    c.dot(p, 4.0, {label[0] == 'P' ? curve_blue : ink, "none", 0.0, 1.0});
    c.text(p + P2(off, off), label, 16.0, ink);
  }
  c.text(0.5 * (q1 + q2) + P2(off, -2.5 * off), "L", 16.0, ink);
  c.text(P2(view.lo[0], view.hi[1] - 0.06 * half), "Fig. 6: boundary quadrant Q2 Q1 P1 P2 by projection", 14.0, ink);
  const std::string file = "fig06-boundary-quadrant.svg";
  c.write(dir / file);
  std::ostringstream cap;
  cap << "One boundary quadrant close up (a four-sided one on a curved part): the free edge L = Q1 Q2 of interior quadrant "
         "\"1\", the closest points P1, P2 on the curve (paper eq. 1, Newton-Raphson), the projection segments "
         "(red) that must not cross other quadrants, and the boundary segment P1 P2 that becomes a boundary "
         "element. |Q1 P1| = "
      << fmt("%.3g", (p1 - q1).norm()) << ", |Q2 P2| = " << fmt("%.3g", (p2 - q2).norm())
      << ", |L| = " << fmt("%.3g", (q2 - q1).norm()) << ".";
  return {"6", file, cap.str()};
}

/// Figure 10: the boundary quadrants alone (smoothed positions: the FE mesh keeps the complex's
/// node ids).
Figure boundary_quadrants_alone_figure(const CurveBoundary& curve, const Result2d& r, const fs::path& dir) {
  SvgCanvas c;
  c.set_view(curve.root_box());
  std::size_t n_tri = 0, n_five = 0;
  for (const BoundaryQuadrant& b : r.complex.boundary) {
    std::vector<P2> poly;
    for (std::int32_t v : b.polygon()) poly.push_back(r.fe.mesh.points[std::size_t(v)]);
    c.polygon(poly, {boundary_fill, ink, 0.5, 1.0});
    n_tri += b.is_triangle();
    n_five += b.corner >= 0;
  }
  draw_curve(c, curve, 0.8);
  c.text(P2(curve.root_box().lo[0], curve.root_box().hi[1]),
         "Fig. 10: boundary quadrants: " + std::to_string(r.complex.boundary.size()), 14.0, ink);
  const std::string file = "fig10-boundary-quadrants-alone.svg";
  c.write(dir / file);
  std::ostringstream cap;
  cap << "The boundary quadrants alone, after smoothing: " << r.complex.boundary.size() << " ("
      << r.complex.boundary.size() - n_tri - n_five << " four-sided, " << n_tri << " triangles where P1 = P2, " << n_five
      << " with an inserted corner node); the only quadrants with a side on the interface.";
  return {"10", file, cap.str()};
}

/// A one-quadrant QuadrantComplex: the unit square at `origin` with hanging nodes at the
/// midpoints of the edges in `hanging` (0 bottom, 1 right, 2 top, 3 left, counter-clockwise).
QuadrantComplex one_interior_quadrant(const P2& origin, const std::vector<int>& hanging) {
  QuadrantComplex qc;
  const P2 corner[4] = {origin, origin + P2(1, 0), origin + P2(1, 1), origin + P2(0, 1)};
  InteriorQuadrant q;
  q.level = 1;
  for (int k = 0; k < 4; ++k) {
    q.corner_slot[std::size_t(k)] = std::uint8_t(q.ring.size());
    q.ring.push_back(qc.add_node(corner[k], NodeKind::Interior));
    if (std::find(hanging.begin(), hanging.end(), k) != hanging.end())
      q.ring.push_back(qc.add_node(0.5 * (corner[k] + corner[(k + 1) % 4]), NodeKind::Interior));
  }
  qc.interior.push_back(q);
  return qc;
}

/// A one-quadrant QuadrantComplex holding a boundary quadrant Q2 Q1 P1 P2 (P1 == P2 when
/// `triangle`). The curve locations carry the points themselves, so the quad split's curve
/// midpoint can be the straight midpoint.
QuadrantComplex one_boundary_quadrant(const P2& origin, bool triangle) {
  QuadrantComplex qc;
  auto on_curve = [&](const P2& p) {
    BoundaryLocation w;
    w.patch = 0;
    w.param[0] = p[0];
    w.param[1] = p[1];
    return qc.add_node(p, NodeKind::Boundary, w);
  };
  BoundaryQuadrant b;
  b.node[0] = qc.add_node(origin + P2(0.0, 0.0), NodeKind::Chain);
  b.node[1] = qc.add_node(origin + P2(1.0, 0.0), NodeKind::Chain);
  if (triangle) {
    b.node[2] = b.node[3] = on_curve(origin + P2(0.5, 0.8));
  } else {
    b.node[2] = on_curve(origin + P2(1.1, 0.85));
    b.node[3] = on_curve(origin + P2(-0.15, 0.7));
  }
  b.level = 1;
  qc.boundary.push_back(b);
  return qc;
}

/// Figure 12a: the templates (paper: "only six templates are required for the triangulation of
/// interior quadrants ... we usually need only one template" for boundary quadrants).
Figure templates_figure(const fs::path& dir) {
  SvgCanvas c(900.0, 20.0);
  const std::vector<std::pair<std::string, std::vector<int>>> configs{
      {"no hanging", {}},   {"1 hanging", {0}},       {"2 adjacent", {0, 1}},
      {"2 opposite", {0, 2}}, {"3 hanging", {0, 1, 2}}, {"4 hanging", {0, 1, 2, 3}}};
  const CurveMidpoint straight = [](const BoundaryLocation& a, const BoundaryLocation& b) {
    BoundaryLocation m = a;
    m.param[0] = 0.5 * (a.param[0] + b.param[0]);
    m.param[1] = 0.5 * (a.param[1] + b.param[1]);
    return std::make_pair(P2(m.param[0], m.param[1]), m);
  };
  const ElementKind kinds[3] = {ElementKind::Tri, ElementKind::Mixed, ElementKind::Quad};
  std::ostringstream counts;
  for (int row = 0; row < 3; ++row) {
    const double y = -1.6 * row;
    c.text(P2(-1.1, y + 0.45), name(kinds[row]), 16.0, ink);
    counts << (row ? "; " : "") << name(kinds[row]) << ":";
    for (int col = 0; col < 8; ++col) {
      const P2 origin(1.5 * col, y);
      const QuadrantComplex qc = col < 6 ? one_interior_quadrant(origin, configs[std::size_t(col)].second)
                                         : one_boundary_quadrant(origin, col == 7);
      const FeBeMesh m = fe_be_mesh(qc, kinds[row], straight);
      for (std::size_t e = 0; e < m.mesh.solid.size(); ++e) {
        const ElemId id{std::int32_t(e)};
        std::vector<P2> poly;
        for (int k = 0; k < m.mesh.solid.n_nodes_of(id); ++k) poly.push_back(m.mesh.points[std::size_t(m.mesh.solid.nodes(id)[k].v)]);
        c.polygon(poly, {poly.size() == 3 ? interior_fill : boundary_fill, ink, 0.8, 1.0});
      }
      for (std::size_t e = 0; e < m.mesh.interface.size(); ++e) {
        const VertexId* v = m.mesh.interface.nodes(ElemId{std::int32_t(e)});
        c.line(m.mesh.points[std::size_t(v[0].v)], m.mesh.points[std::size_t(v[1].v)], {"none", control_green, 2.5, 1.0});
      }
      for (const InteriorQuadrant& q : qc.interior)
        for (std::size_t k = 0; k < q.ring.size(); ++k)
          if (std::find(q.corner_slot.begin(), q.corner_slot.end(), k) == q.corner_slot.end())
            c.dot(qc.points[std::size_t(q.ring[k])], 3.0, {corner_red, "none", 0.0, 1.0});
      counts << " " << m.mesh.solid.size();
      if (row == 0)
        c.text(origin + P2(0.0, 1.25), col < 6 ? configs[std::size_t(col)].first : col == 6 ? "boundary" : "P1 = P2",
               12.0, ink);
    }
  }
  c.text(P2(-1.1, 1.7), "Fig. 12a: templates (interior quadrants by hanging nodes, red; boundary quadrants; green: BE)",
         14.0, ink);
  const std::string file = "fig12a-templates.svg";
  c.write(dir / file);
  return {"12a", file,
          "The templates of dim2/templates2d: the six configurations of hanging nodes (red) of a 2:1 balanced "
          "quadrant (up to symmetry), a four-sided boundary quadrant and the P1 = P2 triangle, for tri, mixed and "
          "quad meshes (quad splits the mixed elements once more; green: the BE edge). Elements per template, in "
          "the order shown: " +
              counts.str() + "."};
}

/// Runs the pipeline on one example and writes its figures and index.md; returns a summary line.
std::string figures_for(const std::string& input, const fs::path& out, const std::string& first_number) {
  const std::string stem = fs::path(input).stem().string();
  const fs::path dir = out / stem;
  fs::remove_all(dir);
  fs::create_directories(dir);
  CurveBoundary curve(read_domain(input));
  Options2d opt;  // the file's level and element kind default (tri), the paper's 4 smoothing passes
  opt.keep_stages = true;
  opt.n_threads = 1;
  const double level = curve.global_level() != no_level ? curve.global_level() : curve.domain().default_level;
  std::cout << "\n== " << stem << ": " << curve.n_loops() << " loops, " << curve.corners().size()
            << " corners, level " << level << "\n";
  const Result2d r = mesh2d(curve, opt);

  ValidateOptions<2> vo;
  vo.expected_euler = curve.n_components() - curve.n_holes();
  vo.boundary_distance = [&](const P2& p) { return curve.closest_point(p).distance; };
  const Box<2> bb = curve.bounding_box();
  vo.boundary_tolerance = 1e-10 * (bb.hi - bb.lo).norm();
  const ValidationReport valid = validate<2>(r.fe.mesh, vo);

  // The pipeline's own stage figures, renamed to the paper's numbers.
  const fs::path stages = dir / "stages";
  write_stage_figures(r, curve, stages);
  std::size_t n_in = 0;
  for (auto f : r.interior) n_in += f;
  const Mesh<2>& m = r.fe.mesh;
  struct Stage {
    std::string from, number, to, caption;
  };
  const std::vector<Stage> stage_figures{
      {"01-subdivision.svg", "3", "fig03-subdivision.svg",
       "First step of quadrant generation (check_and_subdivide_quadrant): " + std::to_string(r.subdivided.n_leaves()) +
           " quadrants."},
      {"02-balanced.svg", "4", "fig04-one-level-difference.svg",
       "After the one-level-difference rule (2:1 balance): " + std::to_string(r.balanced.n_leaves()) + " quadrants."},
      {"03-interior-quadrants.svg", "5", "fig05-interior-quadrants.svg",
       "Interior quadrants selected (shaded): " + std::to_string(n_in) + " of " + std::to_string(r.tree.n_leaves()) +
           " leaves, after " + std::to_string(r.n_buffer_dropped) + " dropped by the buffer rule, " +
           std::to_string(r.n_pinches_dropped) + " by the pinch rule, and " + std::to_string(r.n_repairs) +
           " local repairs."},
      {"04-boundary-quadrants.svg", "7", "fig07-boundary-quadrants.svg",
       "Interior and boundary quadrants after the first step of boundary quadrant generation (before corner "
       "pulling): " +
           std::to_string(r.before_pulling.boundary.size()) + " boundary quadrants on " +
           std::to_string(r.stats.n_free_edges) + " free edges; " + std::to_string(r.stats.n_next_normal) +
           " projections took another normal, " + std::to_string(r.stats.n_walked) + " walked along the curve."},
      {"05-corner-pulling.svg", "8", "fig08-corner-pulling.svg",
       "After pulling to corners: " + std::to_string(r.stats.n_corners_pulled) + " nodes pulled onto corner points, " +
           std::to_string(r.stats.n_corners_inserted) + " corners inserted between two boundary nodes, " +
           std::to_string(r.stats.n_corners_missed) + " missed (of " + std::to_string(curve.corners().size()) +
           " corners)."},
      {"06-smoothing.svg", "9", "fig09-smoothing.svg",
       "After Laplacian smoothing (" + std::to_string(opt.smoothing_iterations) +
           " iterations, boundary nodes fixed on the curve)."},
      {"07-boundary-elements.svg", "11", "fig11-boundary-elements.svg",
       "Boundary elements: " + std::to_string(m.interface.size()) +
           " two-node elements on the curve, whose nodes are the FE mesh's boundary nodes."},
      {"08-final-mesh.svg", "12", "fig12-solid-mesh.svg",
       "The solid FE mesh (" + std::string(name(opt.elements)) + "): " + std::to_string(m.solid.size()) +
           " elements, " + std::to_string(m.points.size()) + " nodes (shaded by origin: interior / boundary "
           "quadrants), " + std::to_string(r.n_flips) + " edge flips in the quality pass; " +
           (valid.valid ? "valid" : "NOT valid: " + valid.summary()) + "."},
  };
  std::vector<Figure> figures;
  figures.push_back(control_points_figure(curve, dir, first_number));
  figures.push_back(control_parameter_figure(curve, dir));
  for (const Stage& s : stage_figures) {
    // figures2d names its files by stage; one it no longer writes is reported, not fatal.
    if (!fs::exists(stages / s.from)) {
      figures.push_back({s.number, "-", "missing: dim2/figures2d wrote no " + s.from + ". " + s.caption});
      continue;
    }
    fs::rename(stages / s.from, dir / s.to);
    figures.push_back({s.number, s.to, s.caption});
  }
  fs::remove_all(stages);
  figures.push_back(boundary_quadrant_figure(curve, r.before_pulling, dir));
  figures.push_back(boundary_quadrants_alone_figure(curve, r, dir));
  figures.push_back(templates_figure(dir));
  auto order = [](const Figure& f) { return std::stod(f.number) + (std::isalpha(f.number.back()) ? 0.5 : 0.0); };
  std::stable_sort(figures.begin(), figures.end(), [&](const Figure& a, const Figure& b) { return order(a) < order(b); });

  std::ostringstream md;
  md << "# Paper figures: " << stem << "\n\n"
     << "`" << fs::path(input).filename().string() << "` at level " << level << ", " << name(opt.elements)
     << " elements, " << opt.smoothing_iterations << " smoothing iterations. Numbers follow the paper (Figures 1-12; "
        "'a' marks figures the paper describes but does not draw).\n\n"
     << "| figure | file | what it shows |\n|---|---|---|\n";
  for (const Figure& f : figures) md << "| " << f.number << " | [" << f.file << "](" << f.file << ") | " << f.caption << " |\n";
  std::ofstream(dir / "index.md") << md.str();
  for (const Figure& f : figures) std::cout << "  Fig. " << f.number << ": " << f.file << "\n";
  std::cout << "  " << m.solid.size() << " elements, " << m.interface.size() << " BE elements, "
            << (valid.valid ? "valid" : "NOT VALID") << "\n";
  return "| [" + stem + "](" + stem + "/index.md) | " + std::to_string(m.solid.size()) + " | " +
         std::to_string(m.interface.size()) + " | " + (valid.valid ? "yes" : "no") + " |";
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path out = argc > 1 ? fs::path(argv[1]) : fs::path(FEBEMESH_SOURCE_DIR) / "results/paper_figures";
  std::vector<std::string> inputs;
  for (int i = 2; i < argc; ++i) inputs.push_back(argv[i]);
  if (inputs.empty())
    inputs = {std::string(FEBEMESH_SOURCE_DIR) + "/examples/bracket.json",
              std::string(FEBEMESH_SOURCE_DIR) + "/examples/flange.json"};
  fs::create_directories(out);
  std::cout << "The paper's Figures 1-12 for " << inputs.size() << " examples, into " << out.string() << "\n";
  std::ostringstream md;
  md << "# The paper's Figures 1-12\n\nThe first example plays the paper's Figure 1, the second its Figure 2 and "
        "the stage-by-stage Figures 3-12.\n\n| example | FE elements | BE elements | valid |\n|---|---:|---:|---|\n";
  int failures = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    try {
      md << figures_for(inputs[i], out, i == 0 ? "1" : "2") << "\n";
    } catch (const std::exception& e) {
      ++failures;
      std::cout << "  FAILED: " << e.what() << "\n";
      md << "| " << fs::path(inputs[i]).stem().string() << " | failed: " << e.what() << " | | |\n";
    }
  }
  std::ofstream(out / "index.md") << md.str();
  std::cout << "wrote " << (out / "index.md").string() << "\n";
  return failures == 0 ? 0 : 1;
}
