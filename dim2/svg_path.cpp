#include "dim2/svg_path.hpp"

#include <Eigen/SVD>
#include <charconv>
#include <cmath>
#include <numbers>

namespace febemesh::dim2 {

double Affine::stretch() const {
  Eigen::JacobiSVD<Eigen::Matrix2d> svd(a);
  return svd.singularValues()(0);
}

namespace {

bool is_wsp(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f'; }

/// A cursor over an attribute value with SVG's number and separator rules.
class Scanner {
 public:
  explicit Scanner(std::string_view s) : s_(s) {}

  std::size_t pos() const { return i_; }
  bool at_end() const { return i_ >= s_.size(); }
  char peek() const { return at_end() ? '\0' : s_[i_]; }
  void advance() { ++i_; }
  void skip_wsp() {
    while (!at_end() && is_wsp(peek())) ++i_;
  }
  /// Whitespace with at most one comma.
  void skip_comma_wsp() {
    skip_wsp();
    if (peek() == ',') {
      ++i_;
      skip_wsp();
    }
  }
  bool number_ahead() const {
    char c = peek();
    return std::isdigit(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
  }

  /// One number per the SVG grammar: sign? (digits ('.' digits?)? | '.' digits) exponent?
  double number(const char* what) {
    std::size_t b = i_;
    if (at_end()) throw PathDataError(i_, std::string("path data ends where ") + what + " was expected");
    if (peek() == '+' || peek() == '-') ++i_;
    std::size_t mant = i_;
    while (std::isdigit(static_cast<unsigned char>(peek()))) ++i_;
    bool int_digits = i_ > mant;
    bool frac_digits = false;
    if (peek() == '.') {
      ++i_;
      std::size_t f = i_;
      while (std::isdigit(static_cast<unsigned char>(peek()))) ++i_;
      frac_digits = i_ > f;
    }
    if (!int_digits && !frac_digits) {
      char c = static_cast<char>(std::tolower(static_cast<unsigned char>(s_[mant < s_.size() ? mant : b])));
      if (mant < s_.size() && (c == 'n' || c == 'i'))
        throw PathDataError(b, std::string("not a finite number where ") + what + " was expected (NaN and infinity are refused)");
      throw PathDataError(b, std::string("expected ") + what);
    }
    if (peek() == 'e' || peek() == 'E') {
      std::size_t e = i_ + 1;
      if (e < s_.size() && (s_[e] == '+' || s_[e] == '-')) ++e;
      if (e < s_.size() && std::isdigit(static_cast<unsigned char>(s_[e]))) {
        i_ = e;
        while (std::isdigit(static_cast<unsigned char>(peek()))) ++i_;
      }
    }
    // from_chars accepts no leading '+'.
    std::size_t cb = (s_[b] == '+') ? b + 1 : b;
    double v = 0.0;
    auto [ptr, ec] = std::from_chars(s_.data() + cb, s_.data() + i_, v);
    if (ec == std::errc::result_out_of_range) {
      // Underflow to zero is harmless; overflow is not.
      bool tiny = false;
      auto epos = s_.substr(cb, i_ - cb).find_first_of("eE");
      if (epos != std::string_view::npos && s_[cb + epos + 1] == '-') tiny = true;
      if (!tiny) throw PathDataError(b, "number '" + std::string(s_.substr(b, i_ - b)) + "' overflows");
      v = 0.0;
    } else if (ec != std::errc() || ptr != s_.data() + i_) {
      throw PathDataError(b, "malformed number '" + std::string(s_.substr(b, i_ - b)) + "'");
    }
    if (!std::isfinite(v) || std::abs(v) > max_coordinate)
      throw PathDataError(b, "number '" + std::string(s_.substr(b, i_ - b)) + "' exceeds the largest accepted magnitude 1e15");
    return v;
  }

  bool flag() {
    char c = peek();
    if (c != '0' && c != '1') throw PathDataError(i_, "expected an arc flag (0 or 1)");
    ++i_;
    return c == '1';
  }

 private:
  std::string_view s_;
  std::size_t i_ = 0;
};

void check_point(const P2& p, std::size_t offset) {
  if (!(std::abs(p.x()) <= max_coordinate && std::abs(p.y()) <= max_coordinate))
    throw PathDataError(offset, "coordinates exceed the largest accepted magnitude 1e15");
}

double deg2rad(double d) { return d * std::numbers::pi / 180.0; }

}  // namespace

Affine parse_transform(std::string_view text) {
  Scanner sc(text);
  Affine total;
  sc.skip_wsp();
  while (!sc.at_end()) {
    std::size_t start = sc.pos();
    std::string name;
    while (std::isalpha(static_cast<unsigned char>(sc.peek()))) {
      name += sc.peek();
      sc.advance();
    }
    if (name.empty()) throw PathDataError(start, "expected a transform name");
    sc.skip_wsp();
    if (sc.peek() != '(') throw PathDataError(sc.pos(), "expected '(' after " + name);
    sc.advance();
    sc.skip_wsp();
    std::vector<double> v;
    while (sc.peek() != ')') {
      if (sc.at_end()) throw PathDataError(sc.pos(), "unterminated " + name + "(...)");
      v.push_back(sc.number("a transform argument"));
      sc.skip_comma_wsp();
    }
    sc.advance();
    auto need = [&](std::size_t lo, std::size_t hi) {
      if (v.size() < lo || v.size() > hi)
        throw PathDataError(start, name + "() takes " + std::to_string(lo) + (lo == hi ? "" : " to " + std::to_string(hi)) +
                                       " arguments, got " + std::to_string(v.size()));
    };
    Affine t;
    if (name == "matrix") {
      need(6, 6);
      t.a << v[0], v[2], v[1], v[3];
      t.b = P2(v[4], v[5]);
    } else if (name == "translate") {
      need(1, 2);
      t.b = P2(v[0], v.size() > 1 ? v[1] : 0.0);
    } else if (name == "scale") {
      need(1, 2);
      t.a << v[0], 0, 0, v.size() > 1 ? v[1] : v[0];
    } else if (name == "rotate") {
      if (v.size() != 1 && v.size() != 3) throw PathDataError(start, "rotate() takes 1 or 3 arguments");
      double r = deg2rad(v[0]);
      t.a << std::cos(r), -std::sin(r), std::sin(r), std::cos(r);
      if (v.size() == 3) {
        P2 c(v[1], v[2]);
        t.b = c - t.a * c;
      }
    } else if (name == "skewX") {
      need(1, 1);
      t.a << 1, std::tan(deg2rad(v[0])), 0, 1;
    } else if (name == "skewY") {
      need(1, 1);
      t.a << 1, 0, std::tan(deg2rad(v[0])), 1;
    } else {
      throw PathDataError(start, "unknown transform '" + name + "'");
    }
    if (!t.a.allFinite() || !t.b.allFinite()) throw PathDataError(start, "transform is not finite");
    total = total * t;
    sc.skip_comma_wsp();
  }
  if (total.a(0, 0) * total.a(1, 1) - total.a(0, 1) * total.a(1, 0) == 0.0)
    throw PathDataError(0, "transform is singular (it collapses the drawing)");
  return total;
}

std::vector<Subpath> parse_path_data(std::string_view d) {
  Scanner sc(d);
  std::vector<Subpath> out;
  P2 cur = P2::Zero(), start = P2::Zero();
  P2 last_cubic_ctrl = P2::Zero(), last_quad_ctrl = P2::Zero();
  char prev_cmd = 0;  // uppercase of the previous command, for S and T reflection
  char cmd = 0;
  bool pending_reopen = false;  // a drawing command after Z starts a new subpath at `start`

  auto add = [&](PathSegment seg) {
    if (pending_reopen) {
      Subpath sp;
      sp.offset = seg.offset;
      out.push_back(sp);
      pending_reopen = false;
    }
    for (const auto& p : seg.p) check_point(p, seg.offset);
    out.back().segments.push_back(seg);
  };

  sc.skip_wsp();
  if (sc.at_end()) return out;
  while (true) {
    sc.skip_wsp();
    if (sc.at_end()) break;
    std::size_t cmd_pos = sc.pos();
    char c = sc.peek();
    if (std::isalpha(static_cast<unsigned char>(c))) {
      if (std::string_view("MmLlHhVvCcSsQqTtAaZz").find(c) == std::string_view::npos)
        throw PathDataError(cmd_pos, std::string("unknown path command '") + c + "'");
      cmd = c;
      sc.advance();
      sc.skip_wsp();
    } else if (cmd == 0) {
      throw PathDataError(cmd_pos, "path data must start with a moveto (M or m)");
    } else if (cmd == 'Z' || cmd == 'z') {
      throw PathDataError(cmd_pos, "unexpected number after closepath");
    } else if (!sc.number_ahead()) {
      throw PathDataError(cmd_pos, std::string("unexpected character '") + c + "'");
    }
    // Repeats of a command reuse its letter (a moveto repeats as a lineto).
    if (out.empty() && cmd != 'M' && cmd != 'm') throw PathDataError(cmd_pos, "path data must start with a moveto (M or m)");
    const bool rel = std::islower(static_cast<unsigned char>(cmd));
    const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(cmd)));
    auto pt = [&](const char* what) {
      double x = sc.number(what);
      sc.skip_comma_wsp();
      double y = sc.number(what);
      sc.skip_comma_wsp();
      P2 p(x, y);
      return rel ? P2(cur + p) : p;
    };
    PathSegment seg;
    seg.offset = cmd_pos;
    seg.p[0] = cur;
    switch (up) {
      case 'M': {
        P2 p = pt("a moveto coordinate");
        check_point(p, cmd_pos);
        Subpath sp;
        sp.offset = cmd_pos;
        out.push_back(sp);
        pending_reopen = false;
        cur = start = p;
        cmd = rel ? 'l' : 'L';  // implicit repeats are linetos
        prev_cmd = 'M';
        continue;
      }
      case 'Z': {
        if (!pending_reopen) {
          out.back().closed = true;
          cur = start;
          pending_reopen = true;
        }
        prev_cmd = 'Z';
        continue;
      }
      case 'L':
        seg.kind = PathSegment::Kind::Line;
        seg.p[3] = pt("a lineto coordinate");
        break;
      case 'H': {
        seg.kind = PathSegment::Kind::Line;
        double x = sc.number("a horizontal lineto coordinate");
        sc.skip_comma_wsp();
        seg.p[3] = P2(rel ? cur.x() + x : x, cur.y());
        break;
      }
      case 'V': {
        seg.kind = PathSegment::Kind::Line;
        double y = sc.number("a vertical lineto coordinate");
        sc.skip_comma_wsp();
        seg.p[3] = P2(cur.x(), rel ? cur.y() + y : y);
        break;
      }
      case 'C':
        seg.kind = PathSegment::Kind::Cubic;
        seg.p[1] = pt("a curveto coordinate");
        seg.p[2] = pt("a curveto coordinate");
        seg.p[3] = pt("a curveto coordinate");
        break;
      case 'S':
        seg.kind = PathSegment::Kind::Cubic;
        seg.p[1] = (prev_cmd == 'C' || prev_cmd == 'S') ? P2(2.0 * cur - last_cubic_ctrl) : cur;
        seg.p[2] = pt("a smooth curveto coordinate");
        seg.p[3] = pt("a smooth curveto coordinate");
        break;
      case 'Q':
        seg.kind = PathSegment::Kind::Quadratic;
        seg.p[1] = pt("a quadratic curveto coordinate");
        seg.p[3] = pt("a quadratic curveto coordinate");
        break;
      case 'T':
        seg.kind = PathSegment::Kind::Quadratic;
        seg.p[1] = (prev_cmd == 'Q' || prev_cmd == 'T') ? P2(2.0 * cur - last_quad_ctrl) : cur;
        seg.p[3] = pt("a smooth quadratic curveto coordinate");
        break;
      case 'A': {
        seg.kind = PathSegment::Kind::Arc;
        seg.rx = std::abs(sc.number("an arc radius"));
        sc.skip_comma_wsp();
        seg.ry = std::abs(sc.number("an arc radius"));
        sc.skip_comma_wsp();
        seg.rotation_deg = sc.number("an arc rotation");
        sc.skip_comma_wsp();
        seg.large_arc = sc.flag();
        sc.skip_comma_wsp();
        seg.sweep = sc.flag();
        sc.skip_comma_wsp();
        seg.p[3] = pt("an arc end point");
        break;
      }
      default:
        throw PathDataError(cmd_pos, "internal: unhandled command");  // unreachable: letters checked above
    }
    if (seg.kind == PathSegment::Kind::Quadratic) {
      seg.p[2] = seg.p[3];
      last_quad_ctrl = seg.p[1];
    }
    if (seg.kind == PathSegment::Kind::Cubic) last_cubic_ctrl = seg.p[2];
    if (seg.kind == PathSegment::Kind::Line || seg.kind == PathSegment::Kind::Arc) {
      seg.p[1] = seg.p[0];
      seg.p[2] = seg.p[3];
    }
    prev_cmd = up;
    add(seg);
    cur = seg.p[3];
  }
  return out;
}

Bezier straight_cubic(const P2& a, const P2& b) {
  return Bezier{a, P2((2.0 * a + b) / 3.0), P2((a + 2.0 * b) / 3.0), b};
}

Bezier elevate_quadratic(const P2& a, const P2& c, const P2& b) {
  return Bezier{a, P2(a + 2.0 / 3.0 * (c - a)), P2(b + 2.0 / 3.0 * (c - b)), b};
}

double arc_radial_error_bound(double sweep) {
  double q = std::abs(sweep) / 4.0;
  double s = std::sin(q), c = std::cos(q);
  return 4.0 / 27.0 * std::pow(s, 6) / (c * c);
}

namespace {

/// SVG 1.1 F.6.5-F.6.6: endpoint to centre parameterisation, with out-of-range radii scaled up.
void append_arc(const PathSegment& s, const Affine& m, double tolerance, std::vector<Bezier>& out) {
  const P2 p1 = s.p[0], p2 = s.p[3];
  if (p1 == p2) return;  // SVG: an arc to the current point is omitted
  double rx = s.rx, ry = s.ry;
  if (rx == 0.0 || ry == 0.0) {
    out.push_back(straight_cubic(m(p1), m(p2)));
    return;
  }
  const double phi = deg2rad(std::fmod(s.rotation_deg, 360.0));
  const double cp = std::cos(phi), sp = std::sin(phi);
  const P2 h = 0.5 * (p1 - p2);
  const P2 q(cp * h.x() + sp * h.y(), -sp * h.x() + cp * h.y());
  double lambda = (q.x() * q.x()) / (rx * rx) + (q.y() * q.y()) / (ry * ry);
  if (lambda > 1.0) {
    rx *= std::sqrt(lambda);
    ry *= std::sqrt(lambda);
  }
  const double num = rx * rx * ry * ry - rx * rx * q.y() * q.y() - ry * ry * q.x() * q.x();
  const double den = rx * rx * q.y() * q.y() + ry * ry * q.x() * q.x();
  double coef = std::sqrt(std::max(0.0, num / den));
  if (s.large_arc == s.sweep) coef = -coef;
  const P2 cq(coef * rx * q.y() / ry, -coef * ry * q.x() / rx);
  const P2 centre(cp * cq.x() - sp * cq.y() + 0.5 * (p1.x() + p2.x()), sp * cq.x() + cp * cq.y() + 0.5 * (p1.y() + p2.y()));
  auto angle = [](const P2& u, const P2& v) { return std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v)); };
  const P2 u((q.x() - cq.x()) / rx, (q.y() - cq.y()) / ry);
  const P2 v((-q.x() - cq.x()) / rx, (-q.y() - cq.y()) / ry);
  const double theta1 = angle(P2(1.0, 0.0), u);
  double dtheta = angle(u, v);
  if (!s.sweep && dtheta > 0) dtheta -= 2.0 * std::numbers::pi;
  if (s.sweep && dtheta < 0) dtheta += 2.0 * std::numbers::pi;

  // The cubic approximates the unit circle within e(delta); the ellipse stretches that by at most
  // max(rx, ry), the transform by its spectral norm.
  const double scale = std::max(rx, ry) * m.stretch();
  int n = std::max(1, static_cast<int>(std::ceil(std::abs(dtheta) / (std::numbers::pi / 2.0))));
  while (scale * arc_radial_error_bound(dtheta / n) > tolerance) {
    n *= 2;
    if (n > (1 << 20)) throw PathDataError(s.offset, "arc cannot be approximated to the requested tolerance");
  }
  const double delta = dtheta / n;
  const double k = 4.0 / 3.0 * std::tan(delta / 4.0);
  auto ellipse = [&](double t) {
    const P2 e(rx * std::cos(t), ry * std::sin(t));
    return P2(centre.x() + cp * e.x() - sp * e.y(), centre.y() + sp * e.x() + cp * e.y());
  };
  auto tangent = [&](double t) {
    const P2 e(-rx * std::sin(t), ry * std::cos(t));
    return P2(cp * e.x() - sp * e.y(), sp * e.x() + cp * e.y());
  };
  P2 a = p1;
  for (int i = 0; i < n; ++i) {
    const double ta = theta1 + i * delta, tb = theta1 + (i + 1) * delta;
    const P2 b = (i + 1 == n) ? p2 : ellipse(tb);  // the end points are the file's, exactly
    out.push_back(Bezier{m(a), m(P2(a + k * tangent(ta))), m(P2(b - k * tangent(tb))), m(b)});
    a = b;
  }
}

bool is_degenerate(const Bezier& b) { return b[0] == b[1] && b[1] == b[2] && b[2] == b[3]; }

}  // namespace

void append_beziers(const PathSegment& s, const Affine& m, double tolerance, std::vector<Bezier>& out) {
  Bezier b;
  switch (s.kind) {
    case PathSegment::Kind::Line:
      b = straight_cubic(m(s.p[0]), m(s.p[3]));
      break;
    case PathSegment::Kind::Quadratic:
      b = elevate_quadratic(m(s.p[0]), m(s.p[1]), m(s.p[3]));
      break;
    case PathSegment::Kind::Cubic:
      b = Bezier{m(s.p[0]), m(s.p[1]), m(s.p[2]), m(s.p[3])};
      break;
    case PathSegment::Kind::Arc:
      append_arc(s, m, tolerance, out);
      return;
  }
  if (!is_degenerate(b)) out.push_back(b);
}

double signed_area(const std::vector<Bezier>& pieces) {
  // 3-point Gauss-Legendre on [0, 1].
  static const double r = std::sqrt(0.6);
  static const double nodes[3] = {0.5 * (1.0 - r), 0.5, 0.5 * (1.0 + r)};
  static const double weights[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  double twice = 0.0;
  if (pieces.empty()) return 0.0;
  const P2 origin = pieces.front()[0];  // the integral is translation invariant; this keeps digits
  for (const auto& raw : pieces) {
    Bezier b = raw;
    for (auto& q : b) q -= origin;
    for (int k = 0; k < 3; ++k) {
      const double t = nodes[k], s = 1.0 - t;
      const P2 p = s * s * s * b[0] + 3.0 * s * s * t * b[1] + 3.0 * s * t * t * b[2] + t * t * t * b[3];
      const P2 d = 3.0 * (s * s * (b[1] - b[0]) + 2.0 * s * t * (b[2] - b[1]) + t * t * (b[3] - b[2]));
      twice += weights[k] * (p.x() * d.y() - p.y() * d.x());
    }
  }
  return 0.5 * twice;
}

}  // namespace febemesh::dim2
