#include "dim2/figures2d.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <span>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "core/quality.hpp"
#include "core/svg_canvas.hpp"
#include "dim2/loop_geometry.hpp"

namespace febemesh::dim2 {
namespace {

namespace fs = std::filesystem;

const std::string ink = "#222222";
const std::string curve_blue = "#1f5fbf";
const std::string interior_fill = "#dbe9f7";
const std::string boundary_fill = "#f7d9a8";
const std::string corner_red = "#c0392b";
const std::string be_green = "#1e8449";

std::vector<P2> sample_loop(const Loop& loop, int per_piece = 12) {
  std::vector<P2> pts;
  for (std::size_t i = 0; i < loop.n_pieces(); ++i)
    for (int s = 0; s < per_piece; ++s) pts.push_back(evaluate(loop, i + double(s) / per_piece));
  pts.push_back(pts.front());
  return pts;
}

void draw_curve(SvgCanvas& c, const CurveBoundary& curve, double width = 1.5) {
  for (const Loop& loop : curve.loops()) c.polyline(sample_loop(loop), {"none", curve_blue, width, 1.0});
}

void draw_corners(SvgCanvas& c, const CurveBoundary& curve) {
  for (const CurveCorner& k : curve.corners()) c.dot(k.point, 3.0, {corner_red, "none", 0.0, 1.0});
}

std::vector<P2> cell_polygon(const Orthtree<2>& t, const Cell<2>& cell) {
  const Box<2> b = geometry(t, cell);
  return {b.lo, P2(b.hi[0], b.lo[1]), b.hi, P2(b.lo[0], b.hi[1])};
}

void draw_tree(SvgCanvas& c, const Orthtree<2>& t, const Flags* in) {
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    const bool kept = in && (*in)[i];
    c.polygon(cell_polygon(t, t.leaf(i)), {kept ? interior_fill : "none", kept ? ink : "#9a9a9a", 0.5, 1.0});
  }
}

std::vector<P2> ring_points(const std::vector<P2>& pts, std::span<const std::int32_t> ids) {
  std::vector<P2> out;
  for (std::int32_t i : ids) out.push_back(pts[i]);
  return out;
}

void draw_complex(SvgCanvas& c, const QuadrantComplex& qc, const std::vector<P2>& pts, bool show_interior = true) {
  if (show_interior)
    for (const InteriorQuadrant& q : qc.interior) c.polygon(ring_points(pts, q.ring), {interior_fill, ink, 0.5, 1.0});
  for (const BoundaryQuadrant& b : qc.boundary) {
    c.polygon(ring_points(pts, b.polygon()), {boundary_fill, ink, 0.5, 1.0});
  }
}

void caption(SvgCanvas& c, const CurveBoundary& curve, const std::string& s) {
  const Box<2> b = curve.root_box();
  c.text(P2(b.lo[0], b.hi[1]), s, 14.0, ink);
}

void save(SvgCanvas& c, const fs::path& dir, const std::string& name, std::vector<fs::path>& written) {
  c.write(dir / name);
  written.push_back(dir / name);
}

}  // namespace

void draw_geometry_figure(const CurveBoundary& curve, const fs::path& file) {
  SvgCanvas c;
  c.set_view(curve.root_box());
  for (const Loop& loop : curve.loops()) {
    std::vector<P2> poly;
    for (const Bezier& q : loop.pieces)
      for (int k = 0; k < 3; ++k) poly.push_back(q[k]);
    poly.push_back(poly.front());
    c.polyline(poly, {"none", "#b0b0b0", 0.6, 1.0});
    for (const P2& p : poly) c.dot(p, 1.5, {"#7f7f7f", "none", 0.0, 1.0});
  }
  draw_curve(c, curve, 2.0);
  draw_corners(c, curve);
  caption(c, curve, "B-spline loops (blue), Bezier control points (grey), corners (red)");
  c.write(file);
}

void write_figures_skipped_note(const fs::path& dir, std::size_t n_elements, std::size_t limit) {
  fs::create_directories(dir);
  std::ofstream out(dir / "README.txt");
  out << "The stage figures were not drawn: the mesh has " << n_elements << " elements, more than the "
      << limit << " that an SVG of every quadrant shows legibly (and drawing them took longer than meshing).\n"
      << "00-geometry.svg shows the input. Rerun with --figures all to draw them anyway, or view mesh.vtu in "
         "ParaView.\n";
  if (!out) throw InputError((dir / "README.txt").string() + ": cannot write");
}

std::vector<fs::path> write_stage_figures(const Result2d& r, const CurveBoundary& curve, const fs::path& dir) {
  fs::create_directories(dir);
  std::vector<fs::path> written;
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_tree(c, r.subdivided, nullptr);
    draw_curve(c, curve);
    caption(c, curve, "3-1 recursive subdivision: " + std::to_string(r.subdivided.n_leaves()) + " quadrants");
    save(c, dir, "01-subdivision.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_tree(c, r.balanced, nullptr);
    draw_curve(c, curve);
    caption(c, curve, "3-2 one-level difference: " + std::to_string(r.balanced.n_leaves()) + " quadrants");
    save(c, dir, "02-balanced.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_tree(c, r.tree, &r.interior);
    draw_curve(c, curve);
    std::size_t n_in = 0;
    for (auto f : r.interior) n_in += f;
    caption(c, curve, "3-3 interior quadrants: " + std::to_string(n_in) + " (after " + std::to_string(r.n_repairs) +
                          " local repairs)");
    save(c, dir, "03-interior-quadrants.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_complex(c, r.before_pulling, r.before_pulling.points);
    draw_curve(c, curve, 1.0);
    draw_corners(c, curve);
    caption(c, curve, "3-4 boundary quadrants by projection (before corner pulling)");
    save(c, dir, "04-boundary-quadrants.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_complex(c, r.complex, r.complex.points);
    draw_curve(c, curve, 1.0);
    draw_corners(c, curve);
    caption(c, curve, "after pulling to corners: " + std::to_string(r.stats.n_corners_pulled) + " pulled, " +
                          std::to_string(r.stats.n_corners_inserted) + " inserted");
    save(c, dir, "05-corner-pulling.svg", written);
  }
  {
    // Quadrant outlines with the smoothed positions: the FE mesh keeps the complex's node ids.
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_complex(c, r.complex, r.fe.mesh.points);
    draw_curve(c, curve, 1.0);
    caption(c, curve, "4 after Laplacian smoothing");
    save(c, dir, "06-smoothing.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    draw_complex(c, r.complex, r.fe.mesh.points, false);
    draw_curve(c, curve, 0.8);
    const Mesh<2>& m = r.fe.mesh;
    for (std::size_t e = 0; e < m.interface.size(); ++e) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
      c.line(m.points[v[0].v], m.points[v[1].v], {"none", be_green, 2.5, 1.0});
      c.dot(m.points[v[0].v], 2.0, {be_green, "none", 0.0, 1.0});
    }
    caption(c, curve, "5 boundary elements: " + std::to_string(m.interface.size()));
    save(c, dir, "07-boundary-elements.svg", written);
  }
  {
    SvgCanvas c;
    c.set_view(curve.root_box());
    const Mesh<2>& m = r.fe.mesh;
    for (std::size_t e = 0; e < m.solid.size(); ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      std::vector<P2> poly;
      for (int k = 0; k < m.solid.n_nodes_of(id); ++k) poly.push_back(m.points[m.solid.nodes(id)[k].v]);
      c.polygon(poly, {m.from_boundary_cell[e] ? boundary_fill : interior_fill, ink, 0.4, 1.0});
    }
    for (std::size_t e = 0; e < m.interface.size(); ++e) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
      c.line(m.points[v[0].v], m.points[v[1].v], {"none", be_green, 1.5, 1.0});
    }
    caption(c, curve, "6 finite element mesh: " + std::to_string(m.solid.size()) + " elements, " +
                          std::to_string(m.points.size()) + " nodes");
    save(c, dir, "08-final-mesh.svg", written);
  }
  {
    const Mesh<2>& m = r.fe.mesh;
    draw_angle_figure(m, curve, dir / "09-angles.svg", "");
    written.push_back(dir / "09-angles.svg");
  }
  return written;
}

void draw_angle_figure(const Mesh<2>& m, const CurveBoundary& curve, const fs::path& file, const std::string& who) {
  // Bins of the smallest corner angle up to the best shape's: 60 deg for a triangle, 90 for a quad.
  const std::array<double, 4> tri_upper{20, 30, 40, 50}, quad_upper{30, 45, 60, 75};
  const std::array<const char*, 5> fill = {"#d62728", "#ff7f0e", "#f2c94c", "#9ed89e", "#2ca02c"};
  std::array<std::size_t, 5> count{};
  bool any_tri = false, any_quad = false;
  SvgCanvas c;
  const Box<2> view = curve.root_box();
  const double h = view.hi[1] - view.lo[1], w = view.hi[0] - view.lo[0];
  // Strips above it for the title and under it for the legend.
  c.set_view(Box<2>{P2(view.lo[0], view.lo[1] - 0.07 * h), P2(view.hi[0], view.hi[1] + 0.04 * h)});
  const bool edges = m.solid.size() <= 20000;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const ElemPoints<2> ep = element_points<2>(m.solid, id, m.points);
    const bool quad = m.solid.type[e] == ElemType::Quad4;
    (quad ? any_quad : any_tri) = true;
    const std::array<double, 4>& upper = quad ? quad_upper : tri_upper;
    const double deg = element_quality<2>(m.solid.type[e], ep.span()).min_angle_deg;
    std::size_t b = 0;
    while (b < upper.size() && !(deg < upper[b])) ++b;
    ++count[b];
    c.polygon(std::vector<P2>(ep.p.begin(), ep.p.begin() + ep.n), {fill[b], edges ? "#555555" : "none", 0.3, 1.0});
  }
  draw_curve(c, curve, 1.0);
  const std::string kinds = any_tri && any_quad ? " (triangles / quads)" : "";
  c.text(P2(view.lo[0], view.hi[1] + 0.015 * h),
         (who.empty() ? "" : who + ": ") + std::to_string(m.solid.size()) + " elements by their smallest corner angle" +
             kinds + "; blue: the curve",
         14.0, ink);
  // A bin's label: its range for the kinds the mesh has ("20-30 / 30-45 deg" when both).
  const auto range = [](const std::array<double, 4>& upper, std::size_t b) {
    char text[32];
    if (b == 0)
      std::snprintf(text, sizeof text, "< %g", upper[0]);
    else if (b == upper.size())
      std::snprintf(text, sizeof text, ">= %g", upper[b - 1]);
    else
      std::snprintf(text, sizeof text, "%g-%g", upper[b - 1], upper[b]);
    return std::string(text);
  };
  std::vector<std::pair<std::string, std::string>> items;
  for (std::size_t b = 0; b < fill.size(); ++b) {
    std::string label = any_quad && !any_tri ? range(quad_upper, b) : range(tri_upper, b);
    if (any_tri && any_quad) label += " / " + range(quad_upper, b);
    items.emplace_back(fill[b], label + " deg: " + std::to_string(count[b]));
  }
  swatch_row(c, P2(view.lo[0], view.lo[1] - 0.055 * h), w / static_cast<double>(fill.size()), 0.025 * h, items);
  c.write(file);
}

}  // namespace febemesh::dim2
