#include "dim2/read_svg.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "dim2/domain_checks.hpp"
#include "dim2/read_domain.hpp"
#include "dim2/svg_path.hpp"
#include "dim2/xml_lite.hpp"

namespace febemesh::dim2 {

namespace {

enum class FillRule { NonZero, EvenOdd };

/// One filled shape: its subpaths in user units, the transform to user units of the root, and
/// where it came from.
struct Shape {
  std::vector<Subpath> subpaths;
  Affine transform;
  FillRule rule = FillRule::NonZero;
  std::string name;  ///< e.g. "path 3 (id=hub)"
  TextPos pos;
};

/// Containers whose content is not rendered by itself.
bool is_unrendered(const std::string& n) {
  static const char* names[] = {"defs", "clipPath", "mask", "symbol", "pattern", "marker", "metadata", "title",
                                "desc", "style", "script", "linearGradient", "radialGradient", "filter", "font"};
  return std::any_of(std::begin(names), std::end(names), [&](const char* x) { return n == x; });
}

std::string trim(std::string_view s) {
  auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  auto e = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(b, e - b + 1));
}

/// The value of CSS property `prop` in a style attribute, if any.
std::optional<std::string> style_property(const XmlElement& e, const std::string& prop) {
  const XmlAttribute* st = e.attribute("style");
  if (!st) return std::nullopt;
  std::string_view s = st->value;
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t semi = s.find(';', i);
    if (semi == std::string_view::npos) semi = s.size();
    std::string_view decl = s.substr(i, semi - i);
    std::size_t colon = decl.find(':');
    if (colon != std::string_view::npos && trim(decl.substr(0, colon)) == prop) return trim(decl.substr(colon + 1));
    i = semi + 1;
  }
  return std::nullopt;
}

class SvgReader {
 public:
  SvgReader(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  Domain read() {
    XmlElement root = parse_xml(text_, source_);
    if (root.local_name() != "svg")
      throw InputError(where(source_, root.pos) + "the root element is <" + root.name + ">, not <svg>");
    visit(root, Affine{}, FillRule::NonZero);
    return build();
  }

 private:
  const std::string& text_;
  const std::string& source_;
  std::vector<Shape> shapes_;
  int n_elements_ = 0;

  [[noreturn]] void fail(TextPos p, const std::string& why) const { throw InputError(where(source_, p) + why); }

  /// Attribute `name`'s path data or transform error, placed inside the attribute value.
  [[noreturn]] void fail_in(const XmlAttribute& a, const PathDataError& e, std::size_t shift = 0) const {
    std::size_t off = e.offset() >= shift ? e.offset() - shift : 0;
    fail(position_in_value(a, off), "bad " + a.name + ": " + e.what());
  }

  double length(const XmlElement& e, const char* name, double fallback) const {
    const XmlAttribute* a = e.attribute(name);
    if (!a) return fallback;
    std::string v = trim(a->value);
    if (v.size() > 2 && v.compare(v.size() - 2, 2, "px") == 0) v.resize(v.size() - 2);
    double x = 0.0;
    const char* b = v.data();
    if (!v.empty() && v[0] == '+') ++b;
    auto [ptr, ec] = std::from_chars(b, v.data() + v.size(), x);
    if (v.empty() || ec != std::errc() || ptr != v.data() + v.size())
      fail(a->value_pos, std::string("attribute ") + name + "=\"" + a->value + "\" is not a length in user units");
    if (!std::isfinite(x) || std::abs(x) > max_coordinate)
      fail(a->value_pos, std::string("attribute ") + name + " exceeds the largest accepted magnitude 1e15");
    return x;
  }

  void visit(const XmlElement& e, const Affine& parent, FillRule parent_rule) {
    const std::string n = e.local_name();
    if (is_unrendered(n)) return;
    if (const XmlAttribute* d = e.attribute("display"); d && trim(d->value) == "none") return;
    if (style_property(e, "display") == std::optional<std::string>("none")) return;

    Affine m = parent;
    if (const XmlAttribute* t = e.attribute("transform")) {
      try {
        m = parent * parse_transform(t->value);
      } catch (const PathDataError& err) {
        fail_in(*t, err);
      }
    }
    if (n == "svg" && n_elements_ > 0) {
      // A nested viewport: its x, y place it; its viewBox scaling is not supported.
      if (e.attribute("viewBox")) fail(e.pos, "nested <svg> with a viewBox is not supported");
      Affine t;
      t.b = P2(length(e, "x", 0.0), length(e, "y", 0.0));
      m = m * t;
    }
    ++n_elements_;
    FillRule rule = parent_rule;
    std::optional<std::string> fr = style_property(e, "fill-rule");
    if (!fr)
      if (const XmlAttribute* a = e.attribute("fill-rule")) fr = trim(a->value);
    if (fr) {
      if (*fr == "evenodd") rule = FillRule::EvenOdd;
      else if (*fr == "nonzero") rule = FillRule::NonZero;
      else if (*fr != "inherit") fail(e.pos, "fill-rule '" + *fr + "' is neither nonzero nor evenodd");
    }

    if (n == "use") fail(e.pos, "<use> is not supported; flatten the drawing (e.g. Inkscape: Edit > Clone > Unlink)");
    if (n == "image" || n == "text") fail(e.pos, "<" + n + "> has no outline geometry; convert it to paths");

    std::vector<Subpath> subpaths;
    if (n == "path") {
      const XmlAttribute* d = e.attribute("d");
      if (!d) fail(e.pos, "<path> without a d attribute");
      try {
        subpaths = parse_path_data(d->value);
      } catch (const PathDataError& err) {
        fail_in(*d, err);
      }
    } else if (n == "polygon" || n == "polyline") {
      const XmlAttribute* pts = e.attribute("points");
      if (!pts) fail(e.pos, "<" + n + "> without a points attribute");
      // The points list is the coordinate list of an implicit-lineto path.
      if (trim(pts->value).empty()) return;
      try {
        subpaths = parse_path_data("M " + pts->value + " Z");
      } catch (const PathDataError& err) {
        fail_in(*pts, err, 2);
      }
    } else if (n == "rect") {
      subpaths = rect(e);
    } else if (n == "circle" || n == "ellipse") {
      subpaths = ellipse(e, n == "circle");
    }
    if (!subpaths.empty()) {
      Shape s;
      s.subpaths = std::move(subpaths);
      s.transform = m;
      s.rule = rule;
      s.pos = e.pos;
      s.name = n + " " + std::to_string(shapes_.size() + 1);
      if (const XmlAttribute* id = e.attribute("id")) s.name += " (id=" + id->value + ")";
      shapes_.push_back(std::move(s));
    }
    for (const auto& c : e.children) visit(c, m, rule);
  }

  static PathSegment line(const P2& a, const P2& b) {
    PathSegment s;
    s.kind = PathSegment::Kind::Line;
    s.p = {a, a, b, b};
    return s;
  }
  static PathSegment arc(const P2& a, const P2& b, double rx, double ry) {
    PathSegment s;
    s.kind = PathSegment::Kind::Arc;
    s.p = {a, a, b, b};
    s.rx = rx;
    s.ry = ry;
    s.sweep = true;
    return s;
  }

  std::vector<Subpath> rect(const XmlElement& e) const {
    const double x = length(e, "x", 0.0), y = length(e, "y", 0.0);
    const double w = length(e, "width", 0.0), h = length(e, "height", 0.0);
    if (w < 0 || h < 0) fail(e.pos, "<rect> with a negative width or height");
    if (w == 0 || h == 0) fail(e.pos, "<rect> with zero width or height encloses no area");
    double rx = length(e, "rx", -1.0), ry = length(e, "ry", -1.0);
    if (rx < 0 && ry < 0) rx = ry = 0.0;
    else if (rx < 0) rx = ry;
    else if (ry < 0) ry = rx;
    rx = std::min(rx, w / 2);
    ry = std::min(ry, h / 2);
    Subpath sp;
    sp.closed = true;
    auto& g = sp.segments;
    if (rx == 0 || ry == 0) {
      const P2 c[4] = {P2(x, y), P2(x + w, y), P2(x + w, y + h), P2(x, y + h)};
      for (int i = 0; i < 4; ++i) g.push_back(line(c[i], c[(i + 1) % 4]));
    } else {
      // Clockwise in user space (y down), like the SVG spec's rect-to-path.
      const P2 pts[8] = {P2(x + rx, y),     P2(x + w - rx, y),     P2(x + w, y + ry), P2(x + w, y + h - ry),
                         P2(x + w - rx, y + h), P2(x + rx, y + h), P2(x, y + h - ry), P2(x, y + ry)};
      for (int i = 0; i < 8; i += 2) {
        if (pts[i] != pts[i + 1]) g.push_back(line(pts[i], pts[i + 1]));
        g.push_back(arc(pts[i + 1], pts[(i + 2) % 8], rx, ry));
      }
    }
    return {sp};
  }

  std::vector<Subpath> ellipse(const XmlElement& e, bool circle) const {
    const double cx = length(e, "cx", 0.0), cy = length(e, "cy", 0.0);
    double rx = 0, ry = 0;
    if (circle) {
      rx = ry = length(e, "r", 0.0);
    } else {
      rx = length(e, "rx", 0.0);
      ry = length(e, "ry", 0.0);
    }
    if (rx < 0 || ry < 0) fail(e.pos, "<" + e.local_name() + "> with a negative radius");
    if (rx == 0 || ry == 0) fail(e.pos, "<" + e.local_name() + "> with zero radius encloses no area");
    Subpath sp;
    sp.closed = true;
    const P2 q[4] = {P2(cx + rx, cy), P2(cx, cy + ry), P2(cx - rx, cy), P2(cx, cy - ry)};
    for (int i = 0; i < 4; ++i) sp.segments.push_back(arc(q[i], q[(i + 1) % 4], rx, ry));
    return {sp};
  }

  /// A loop before it becomes a Loop: pieces in mesh coordinates.
  struct Candidate {
    std::vector<Bezier> pieces;
    double area = 0.0;
    std::vector<P2> polyline;  ///< flattened, for winding numbers
    P2 probe = P2::Zero();     ///< a point on the loop away from its junctions
    std::string name;
    TextPos pos;
  };

  /// A point of the mesh's coordinates in the drawing's user units (y down), for messages.
  static std::string user_coords(const P2& p) {
    std::ostringstream os;
    os.precision(9);
    os << "(" << p.x() + 0.0 << ", " << -p.y() + 0.0 << ")";  // (+ 0.0: no "-0")
    return os.str();
  }

  /// Refuses outlines that cross or touch themselves or each other (closer than `tol`, mesh
  /// units), naming them and the place in the drawing's user units. The fill rules below look
  /// at one point of each outline and hold only for outlines that do not cross; the curve kernel
  /// checks only the outlines they keep. So crossing outlines were meshed as some other region
  /// without a word: two overlapping squares in one path (area 112 drawn) as the first square
  /// alone (area 100), the second left out as "filled on both sides" at its probe point.
  void check_outlines(const std::vector<std::vector<Candidate>>& all, double tol) const {
    std::vector<const Candidate*> cands;
    std::vector<Loop> loops;
    for (const std::vector<Candidate>& shape : all)
      for (const Candidate& c : shape) {
        cands.push_back(&c);
        loops.push_back(loop_from_beziers(c.pieces, c.name));
      }
    for (std::size_t k = 0; k < loops.size(); ++k)
      if (const std::optional<P2> p = loop_self_intersection(loops[k], tol))
        fail(cands[k]->pos, cands[k]->name + " crosses or touches itself at " + user_coords(*p));
    if (const std::optional<LoopsMeeting> m = first_loops_intersection(loops, tol))
      fail(cands[m->j]->pos, cands[m->j]->name + " and " + cands[m->i]->name + " cross or touch at " + user_coords(m->at) +
                                 ": outlines must not meet (overlapping shapes are not merged; draw their union as one outline)");
  }

  static P2 eval(const Bezier& b, double t) {
    const double s = 1.0 - t;
    return s * s * s * b[0] + 3.0 * s * s * t * b[1] + 3.0 * s * t * t * b[2] + t * t * t * b[3];
  }

  static std::vector<P2> flatten(const std::vector<Bezier>& pieces, double tol) {
    std::vector<P2> out;
    for (const auto& b : pieces) {
      // Chord error <= max|B''| / (8 n^2), |B''| <= 6 max second difference of the control points.
      const double dd = std::max((b[0] - 2 * b[1] + b[2]).norm(), (b[1] - 2 * b[2] + b[3]).norm());
      const int n = std::clamp(static_cast<int>(std::ceil(std::sqrt(0.75 * dd / tol))), 1, 4096);
      for (int i = 0; i < n; ++i) out.push_back(eval(b, static_cast<double>(i) / n));
    }
    return out;
  }

  /// Winding number of the closed polyline around p (Sunday's crossing rule).
  static int winding(const std::vector<P2>& poly, const P2& p) {
    int w = 0;
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const P2& a = poly[i];
      const P2& b = poly[(i + 1) % n];
      const double cross = (b.x() - a.x()) * (p.y() - a.y()) - (p.x() - a.x()) * (b.y() - a.y());
      if (a.y() <= p.y()) {
        if (b.y() > p.y() && cross > 0) ++w;
      } else {
        if (b.y() <= p.y() && cross < 0) --w;
      }
    }
    return w;
  }

  Domain build() {
    // The drawing's size, from every control point in root user units: sets the arc tolerance.
    Box<2> box = Box<2>::empty();
    for (const auto& s : shapes_)
      for (const auto& sp : s.subpaths)
        for (const auto& seg : sp.segments)
          for (const auto& p : seg.p) box.expand(s.transform(p));
    if (shapes_.empty()) throw InputError(source_ + ": no geometry: no path, rect, circle, ellipse, polygon or polyline");
    const double size = std::max(box.extent().norm(), 1e-300);
    if (!std::isfinite(size) || box.extent().maxCoeff() > 2 * max_coordinate)
      throw InputError(source_ + ": the transformed drawing exceeds the largest accepted magnitude 1e15");
    const double tol = svg_arc_tolerance * size;

    Affine flip;  // mesh coordinates are (x, -y) of the user units
    flip.a(1, 1) = -1.0;

    Domain dom;
    dom.source = source_;
    std::vector<std::vector<Candidate>> all(shapes_.size());
    for (std::size_t si = 0; si < shapes_.size(); ++si) {
      const Shape& s = shapes_[si];
      const Affine m = flip * s.transform;
      std::vector<Candidate>& cands = all[si];
      for (std::size_t k = 0; k < s.subpaths.size(); ++k) {
        const Subpath& sp = s.subpaths[k];
        Candidate c;
        c.name = s.name + ", subpath " + std::to_string(k + 1);
        c.pos = s.pos;
        for (const auto& seg : sp.segments) {
          try {
            append_beziers(seg, m, tol, c.pieces);
          } catch (const PathDataError& err) {
            fail(s.pos, c.name + ": " + err.what());
          }
        }
        if (c.pieces.empty()) continue;  // a lone moveto draws nothing
        // Filling closes every subpath; a tiny gap from accumulated relative moves is snapped.
        const P2 first = c.pieces.front()[0];
        P2& last = c.pieces.back()[3];
        if ((last - first).norm() <= 1e-12 * size) {
          const P2 shift = first - last;
          c.pieces.back()[2] += shift;
          last = first;
        } else {
          c.pieces.push_back(straight_cubic(last, first));
        }
        Box<2> own = Box<2>::empty();
        for (const Bezier& b : c.pieces)
          for (const P2& p : b) own.expand(p);
        if (const std::optional<std::string> why = loop_extent_problem(own))
          fail(s.pos, c.name + " near " + user_coords(first) + ": " + *why);
        c.area = signed_area(c.pieces);
        if (std::abs(c.area) <= 1e-14 * size * size)
          fail(s.pos, c.name + " near " + user_coords(first) + ": encloses zero area (a degenerate loop)");
        c.polyline = flatten(c.pieces, 1e-7 * size);
        std::size_t longest = 0;
        double best = -1.0;
        for (std::size_t i = 0; i < c.pieces.size(); ++i) {
          const double len = (c.pieces[i][3] - c.pieces[i][0]).norm();
          if (len > best) {
            best = len;
            longest = i;
          }
        }
        c.probe = eval(c.pieces[longest], 0.5);
        cands.push_back(std::move(c));
      }
    }
    // The curve kernel's tolerance, of the drawing's size.
    check_outlines(all, check_tolerance(box));
    // Which side of each subpath is solid? Just inside it the winding number of its shape is the
    // other subpaths' winding plus its own orientation; just outside, the others' alone. It
    // bounds the shape only if the fill rule fills one side and not the other; it bounds the
    // drawing (the union of the shapes) only if no other shape covers it. No two outlines meet
    // (check_outlines).
    auto filled = [](FillRule rule, int w) { return rule == FillRule::EvenOdd ? (w % 2 != 0) : (w != 0); };
    auto shape_winding = [&](std::size_t si, const P2& p, std::size_t skip) {
      int w = 0;
      for (std::size_t j = 0; j < all[si].size(); ++j)
        if (j != skip) w += winding(all[si][j].polyline, p);
      return w;
    };
    for (std::size_t si = 0; si < shapes_.size(); ++si) {
      for (std::size_t i = 0; i < all[si].size(); ++i) {
        const Candidate& c = all[si][i];
        const int others = shape_winding(si, c.probe, i);
        const int own = c.area > 0 ? 1 : -1;
        const bool in = filled(shapes_[si].rule, others + own), out = filled(shapes_[si].rule, others);
        if (in == out) continue;  // both sides alike: not a boundary of the solid
        bool covered = false;
        for (std::size_t sj = 0; sj < shapes_.size() && !covered; ++sj)
          if (sj != si) covered = filled(shapes_[sj].rule, shape_winding(sj, c.probe, all[sj].size()));
        if (covered) continue;  // inside another shape's solid: the union has no boundary here
        std::vector<Bezier> pieces = c.pieces;
        const bool want_ccw = in;  // solid inside: outer boundary; else a hole
        if (want_ccw != (c.area > 0)) {
          std::reverse(pieces.begin(), pieces.end());
          for (auto& b : pieces) std::reverse(b.begin(), b.end());
        }
        dom.loops.push_back(loop_from_beziers(std::move(pieces), c.name));
      }
    }
    if (dom.loops.empty()) throw InputError(source_ + ": no geometry: no shape encloses a solid region");
    return dom;
  }
};

}  // namespace

Domain parse_svg(const std::string& text, const std::string& source) {
  try {
    return SvgReader(text, source).read();
  } catch (const InputError& e) {
    // The curve kernel names the loop but not the file.
    if (std::string_view(e.what()).substr(0, source.size()) != source) throw InputError(source + ": " + e.what());
    throw;
  }
}

Domain read_svg(const std::string& path) { return parse_svg(read_text_file(path), path); }

}  // namespace febemesh::dim2
