#include "dim3/figures3d.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <span>
#include <sstream>
#include <utility>

#include "core/error.hpp"
#include "core/mesh_topology.hpp"
#include "core/quality.hpp"
#include "core/svg_canvas.hpp"

namespace febemesh::dim3 {
namespace {

using P2 = Point<2>;

/// The points in counter-clockwise order around their mean, repeats (closer than 1e-12 of the
/// spread) dropped: the convex polygon a plane cuts from a convex cell. Fewer than three points
/// left: empty.
std::vector<P2> convex_ring(std::vector<P2> pts) {
  if (pts.size() < 3) return {};
  P2 c = P2::Zero();
  for (const P2& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  std::sort(pts.begin(), pts.end(), [&](const P2& a, const P2& b) {
    return std::atan2(a.y() - c.y(), a.x() - c.x()) < std::atan2(b.y() - c.y(), b.x() - c.x());
  });
  double spread = 0.0;
  for (const P2& p : pts) spread = std::max(spread, (p - c).norm());
  std::vector<P2> out;
  for (const P2& p : pts)
    if (out.empty() || (p - out.back()).norm() > 1e-12 * spread) out.push_back(p);
  while (out.size() > 1 && (out.front() - out.back()).norm() <= 1e-12 * spread) out.pop_back();
  if (out.size() < 3) return {};
  return out;
}

/// Whether an edge whose ends lie at signed distances da and db from the plane crosses it (its
/// ends strictly on both sides).
bool crosses(double da, double db) { return (da < 0 && db > 0) || (da > 0 && db < 0); }

/// Where such an edge ab meets the plane x[axis] = at, in the plane's coordinates.
P2 plane_point(const P3& a, const P3& b, double da, double db, int axis) {
  return section_coordinates(a + (da / (da - db)) * (b - a), axis);
}

/// The crossings of a face's boundary loop by the plane (`d`: the loop's nodes' signed
/// distances, none 0), paired into the face's segments: two crossings make one; four (a quad
/// whose corners alternate sides) make two, joined as the bilinear face's cut joins them, around
/// the corners on the other side from the face's centre. The same pairs from either side of the
/// face and from any first node. Empty when the crossings are not two or four.
template <class Crossing>
std::vector<std::array<int, 2>> face_segments(std::span<const double> d, const Crossing& crossing) {
  const std::size_t n = d.size();
  std::vector<int> found;
  for (std::size_t k = 0; k < n; ++k)
    if (crosses(d[k], d[(k + 1) % n])) found.push_back(crossing(k));
  if (std::find(found.begin(), found.end(), -1) != found.end()) return {};  // not an edge of the element
  if (found.size() == 2) return {{found[0], found[1]}};
  if (found.size() != 4 || n != 4) return {};
  double centre = 0.0;
  for (const double x : d) centre += x;
  // Corner 0 on the centre's side: it joins corner 2 through the middle, and corners 1 and 3
  // are cut off, each by the segment between the crossings of its two edges.
  if ((centre < 0) == (d[0] < 0)) return {{found[0], found[1]}, {found[2], found[3]}};
  return {{found[3], found[0]}, {found[1], found[2]}};
}

/// The polygons the plane cuts from an element none of whose nodes lies on it: its faces'
/// segments between the edge crossings (`edge_nodes`: the crossed edges' local nodes, smaller
/// first; `pts`: where), chained into loops, each counter-clockwise (one loop but where the cut
/// falls apart). Empty when the segments do not close into loops.
std::vector<std::vector<P2>> chained_rings(const Mesh<3>& m, const VertexId* v, ElemType t, int axis, double at,
                                           const std::vector<std::array<int, 2>>& edge_nodes, const std::vector<P2>& pts) {
  const auto crossing = [&](int i, int j) {
    const std::array<int, 2> key{std::min(i, j), std::max(i, j)};
    const auto it = std::find(edge_nodes.begin(), edge_nodes.end(), key);
    return it == edge_nodes.end() ? -1 : static_cast<int>(it - edge_nodes.begin());
  };
  std::vector<std::array<int, 2>> segs;
  for (int f = 0; f < n_facets(t); ++f) {
    const std::span<const int> loop = facet_local_nodes(t, f);
    std::array<double, 4> d{};
    if (loop.size() > d.size()) return {};
    for (std::size_t k = 0; k < loop.size(); ++k) d[k] = m.points[v[loop[k]].v][axis] - at;
    const std::span<const double> ds(d.data(), loop.size());
    const bool crossed = std::any_of(ds.begin(), ds.end(), [](double x) { return x < 0; }) &&
                         std::any_of(ds.begin(), ds.end(), [](double x) { return x > 0; });
    if (!crossed) continue;
    const auto here = face_segments(ds, [&](std::size_t k) { return crossing(loop[k], loop[(k + 1) % loop.size()]); });
    if (here.empty()) return {};
    segs.insert(segs.end(), here.begin(), here.end());
  }
  std::vector<std::vector<P2>> rings;
  std::vector<std::uint8_t> used(segs.size(), 0);
  for (std::size_t first = 0; first < segs.size(); ++first) {
    if (used[first]) continue;
    used[first] = 1;
    std::vector<int> order{segs[first][0], segs[first][1]};
    while (order.back() != order.front()) {
      const int at_point = order.back();
      std::size_t next = segs.size();
      for (std::size_t k = 0; k < segs.size() && next == segs.size(); ++k)
        if (!used[k] && (segs[k][0] == at_point || segs[k][1] == at_point)) next = k;
      if (next == segs.size()) return {};
      used[next] = 1;
      order.push_back(segs[next][0] == at_point ? segs[next][1] : segs[next][0]);
    }
    order.pop_back();
    if (order.size() < 3) return {};
    std::vector<P2> ring;
    for (const int k : order) ring.push_back(pts[static_cast<std::size_t>(k)]);
    double twice = 0.0;
    for (std::size_t k = 0; k < ring.size(); ++k)
      twice += ring[k].x() * ring[(k + 1) % ring.size()].y() - ring[(k + 1) % ring.size()].x() * ring[k].y();
    if (twice < 0) std::reverse(ring.begin(), ring.end());
    rings.push_back(std::move(ring));
  }
  return rings;
}

/// The bins of the smallest dihedral angle the sections are coloured by.
struct AngleBin {
  double below;
  const char* colour;
  const char* label;
};
constexpr AngleBin angle_bins[] = {{10.0, "#d62728", "< 10 deg"},
                                   {20.0, "#ff7f0e", "10-20 deg"},
                                   {30.0, "#f2c94c", "20-30 deg"},
                                   {40.0, "#9ed89e", "30-40 deg"},
                                   {1e300, "#2ca02c", ">= 40 deg"}};
constexpr int n_angle_bins = static_cast<int>(std::size(angle_bins));

int angle_bin(double deg) {
  for (int b = 0; b < n_angle_bins; ++b)
    if (deg < angle_bins[b].below) return b;
  return n_angle_bins - 1;  // NaN
}

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

/// Text lines under a figure whose shapes span `box`; returns the height they take (mesh units).
double caption(SvgCanvas& c, const Box<2>& box, const std::vector<std::string>& lines) {
  const double h = std::max(box.hi.x() - box.lo.x(), box.hi.y() - box.lo.y());
  for (std::size_t k = 0; k < lines.size(); ++k)
    c.text(P2(box.lo.x(), box.lo.y() - (0.05 + 0.04 * static_cast<double>(k)) * h), lines[k], 13.0, "#222222");
  return (0.05 + 0.04 * static_cast<double>(lines.size())) * h;
}

/// A row of colour swatches with their labels under the captions (`below`: their height).
void legend(SvgCanvas& c, const Box<2>& box, double below, const std::vector<std::pair<std::string, std::string>>& items) {
  const double w = box.hi.x() - box.lo.x(), h = std::max(w, box.hi.y() - box.lo.y());
  const double side = 0.025 * h, y = box.lo.y() - below - 0.01 * h;
  swatch_row(c, P2(box.lo.x(), y - side), w / static_cast<double>(std::max<std::size_t>(items.size(), 1)), side, items);
}

void draw_section(const Mesh<3>& m, const Surface& s, int axis, double at, const std::vector<SectionPolygon>& polys,
                  const std::filesystem::path& file, const std::string& who) {
  SvgCanvas c(900.0, 16.0);
  std::array<std::size_t, n_angle_bins> count{};
  Box<2> box = Box<2>::empty();
  const bool edges = polys.size() <= 20000;  // element outlines only where they can be seen
  std::size_t n_elements = 0;
  for (std::size_t k = 0; k < polys.size(); ++k) {
    const SectionPolygon& sp = polys[k];
    const ElemPoints<3> ep = element_points<3>(m.solid, ElemId{sp.element}, m.points);
    const int b = angle_bin(element_quality<3>(m.solid.type[static_cast<std::size_t>(sp.element)], ep.span()).min_angle_deg);
    // An element whose cut falls apart has several polygons, one after the other: counted once.
    if (k == 0 || sp.element != polys[k - 1].element) ++count[static_cast<std::size_t>(b)], ++n_elements;
    SvgStyle st;
    st.fill = angle_bins[b].colour;
    st.stroke = edges ? "#555555" : "none";
    st.stroke_width = 0.3;
    c.polygon(sp.pts, st);
    for (const P2& p : sp.pts) box.expand(p);
  }
  SvgStyle cut;
  cut.stroke = "#000000";
  cut.stroke_width = 1.2;
  for (const auto& seg : section_segments(s, axis, at)) {
    c.line(seg[0], seg[1], cut);
    box.expand(seg[0]), box.expand(seg[1]);
  }
  if (!(box.lo.array() <= box.hi.array()).all()) box = Box<2>{P2::Zero(), P2::Ones()};
  std::ostringstream title;
  title.precision(6);
  title << who << (who.empty() ? "solid" : ": solid") << " cut by the plane " << axis_name(axis) << " = " << at << ": "
        << n_elements << " elements; black: the surface's cut";
  const double below = caption(c, box, {title.str(), "elements by their smallest dihedral angle:"});
  std::vector<std::pair<std::string, std::string>> items;
  for (int b = 0; b < n_angle_bins; ++b)
    items.emplace_back(angle_bins[b].colour,
                       std::string(angle_bins[b].label) + ": " + std::to_string(count[static_cast<std::size_t>(b)]));
  legend(c, box, below, items);
  c.write(file);
}

void draw_interface(const Mesh<3>& m, const std::filesystem::path& file, std::size_t n_visible_limit,
                    std::vector<std::string>& skipped) {
  // Seen from the corner (+x, -y, +z) of the box, z up on the page.
  const P3 eye = P3(1.0, -1.4, 0.9).normalized();
  const P3 look = -eye;
  const P3 right = look.cross(P3(0.0, 0.0, 1.0)).normalized();
  const P3 up = right.cross(look);
  const P3 light = (0.7 * eye + 0.5 * up - 0.3 * right).normalized();
  struct Face {
    double depth;
    std::size_t f;
    double shade;
  };
  std::vector<Face> faces;
  for (std::size_t f = 0; f < m.interface.size(); ++f) {
    const ElemId id{static_cast<std::int32_t>(f)};
    const VertexId* v = m.interface.nodes(id);
    const int n = m.interface.n_nodes_of(id);
    if (n < 3) continue;
    P3 normal = P3::Zero(), centre = P3::Zero();
    for (int k = 0; k < n; ++k) {
      const P3& a = m.points[v[k].v];
      const P3& b = m.points[v[(k + 1) % n].v];
      normal += a.cross(b);  // Newell: quads need not be planar
      centre += a;
    }
    const double len = normal.norm();
    if (!(len > 0) || normal.dot(eye) <= 0) continue;  // outward faces turned away are hidden
    centre /= n;
    faces.push_back({centre.dot(look), f, 0.3 + 0.7 * std::max(0.0, normal.dot(light) / len)});
  }
  if (n_visible_limit > 0 && faces.size() > n_visible_limit) {
    skipped.push_back(file.filename().string() + ": " + std::to_string(faces.size()) + " visible faces, over the limit of " +
                      std::to_string(n_visible_limit));
    return;
  }
  // Far faces first (painter's order; ties by index, so the file is the same every run).
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    return a.depth != b.depth ? a.depth > b.depth : a.f < b.f;
  });
  SvgCanvas c(900.0, 16.0);
  Box<2> box = Box<2>::empty();
  const bool edges = faces.size() <= 30000;
  for (const Face& fc : faces) {
    const ElemId id{static_cast<std::int32_t>(fc.f)};
    const VertexId* v = m.interface.nodes(id);
    std::vector<P2> pts;
    for (int k = 0; k < m.interface.n_nodes_of(id); ++k) {
      const P3& p = m.points[v[k].v];
      pts.emplace_back(p.dot(right), p.dot(up));
      box.expand(pts.back());
    }
    SvgStyle st;
    st.fill = svg_rgb(0.55 * fc.shade + 0.1, 0.65 * fc.shade + 0.1, 0.85 * fc.shade + 0.1);
    st.stroke = edges ? "#1a1a1a" : "none";
    st.stroke_width = 0.25;
    c.polygon(pts, st);
  }
  if (!(box.lo.array() <= box.hi.array()).all()) box = Box<2>{P2::Zero(), P2::Ones()};
  caption(c, box, {"BE mesh (interface) seen from the corner (+x, -y, +z), z up: " + std::to_string(faces.size()) + " of " +
                       std::to_string(m.interface.size()) + " faces face the eye"});
  c.write(file);
}

}  // namespace

Point<2> section_coordinates(const P3& p, int axis) { return P2(p[(axis + 1) % 3], p[(axis + 2) % 3]); }

std::vector<SectionPolygon> section_polygons(const Mesh<3>& m, int axis, double at) {
  std::vector<SectionPolygon> out;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const VertexId* v = m.solid.nodes(id);
    const int n = m.solid.n_nodes_of(id);
    bool below = false, above = false, on = false;
    for (int k = 0; k < n; ++k) {
      const double d = m.points[v[k].v][axis] - at;
      below = below || d < 0;
      above = above || d > 0;
      on = on || d == 0;
    }
    if (!(below && above)) continue;
    const ElemType t = m.solid.type[e];
    // Where the element's edges cross the plane (by edge), then the segment each face's
    // boundary gives, chained into the polygon: a face shared with a neighbour gives both the
    // same segment, so the polygons tile the section even where hexahedra's faces are not flat
    // and the cut is not convex.
    std::vector<std::array<int, 2>> edge_nodes;
    std::vector<P2> pts;
    for (int k = 0; k < n_edges(t); ++k) {
      const auto [i, j] = edge_local_nodes(t, k);
      const P3 &a = m.points[v[i].v], &b = m.points[v[j].v];
      const double da = a[axis] - at, db = b[axis] - at;
      if (!crosses(da, db)) continue;
      edge_nodes.push_back({std::min(i, j), std::max(i, j)});
      pts.push_back(plane_point(a, b, da, db, axis));
    }
    std::vector<std::vector<P2>> rings;
    if (!on) rings = chained_rings(m, v, t, axis, at, edge_nodes, pts);
    if (rings.empty()) {  // a node on the plane (or faces that do not close): the convex hull
      for (int k = 0; k < n; ++k)
        if (m.points[v[k].v][axis] == at) pts.push_back(section_coordinates(m.points[v[k].v], axis));
      rings.push_back(convex_ring(std::move(pts)));
    }
    for (std::vector<P2>& ring : rings)
      if (!ring.empty()) out.push_back({std::move(ring), static_cast<std::int32_t>(e)});
  }
  return out;
}

std::vector<std::array<Point<2>, 2>> section_segments(const Surface& s, int axis, double at) {
  std::vector<std::array<P2, 2>> out;
  for (const Triangle& t : s.triangles()) {
    std::vector<P2> pts;
    for (int k = 0; k < 3; ++k) {
      const P3 &a = s.vertex(t[k]), &b = s.vertex(t[(k + 1) % 3]);
      const double da = a[axis] - at, db = b[axis] - at;
      if (da == 0) pts.push_back(section_coordinates(a, axis));
      if (crosses(da, db)) pts.push_back(plane_point(a, b, da, db, axis));
    }
    if (pts.size() == 2) out.push_back({pts[0], pts[1]});
  }
  return out;
}

double section_plane(const Surface& s, int axis) {
  Box<3> box = Box<3>::empty();
  for (const P3& p : s.vertices()) box.expand(p);
  return 0.5 * (box.lo[axis] + box.hi[axis]) + 0.0123 * (box.hi[axis] - box.lo[axis]);
}

std::size_t write_section_figure(const Mesh<3>& m, const Surface& s, int axis, const std::filesystem::path& file,
                                 std::size_t max_shapes, const std::string& who) {
  const double at = section_plane(s, axis);
  const std::vector<SectionPolygon> polys = section_polygons(m, axis, at);
  if (max_shapes == 0 || polys.size() <= max_shapes) draw_section(m, s, axis, at, polys, file, who);
  return polys.size();
}

MeshFigures write_mesh_figures(const Mesh<3>& m, const Surface& s, const std::filesystem::path& dir,
                               std::size_t max_shapes) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string() + ": cannot create the figures folder: " + ec.message());
  MeshFigures out;
  for (int axis = 0; axis < 3; ++axis) {
    const std::string name = std::string("section-") + axis_name(axis) + ".svg";
    const std::size_t n = write_section_figure(m, s, axis, dir / name, max_shapes);
    if (max_shapes > 0 && n > max_shapes)
      out.skipped.push_back(name + ": " + std::to_string(n) + " polygons, over the limit of " + std::to_string(max_shapes));
    else
      out.written.emplace_back(name);
  }
  const std::size_t n_skipped = out.skipped.size();
  draw_interface(m, dir / "interface.svg", max_shapes, out.skipped);
  if (out.skipped.size() == n_skipped) out.written.emplace_back("interface.svg");
  if (!out.skipped.empty()) {
    std::ofstream note(dir / "README.txt");
    note << "Figures not drawn (an SVG of that many shapes is slow to open and cannot be read;\n"
            "--figures all draws them anyway, or open mesh.vtu in ParaView):\n";
    for (const std::string& why : out.skipped) note << "  " << why << "\n";
    if (!note) throw InputError((dir / "README.txt").string() + ": cannot be written");
  }
  return out;
}

}  // namespace febemesh::dim3
