// Random valid 2D domains for the property suite; see domain_generators.hpp for the regime.

#include "domain_generators.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "dim2/bezier.hpp"
#include "dim2/curve_boundary.hpp"

namespace febemesh::test {

using dim2::ControlPoint;
using dim2::P2;

namespace {

constexpr double pi = 3.14159265358979323846;
constexpr double no_offset = -1.0;  ///< a point with no control level

/// Coordinates on a 1e-4 grid, so the native JSON is short and reads back to the same doubles.
double snap(double v) { return std::round(v * 1e4) / 1e4; }
P2 snap(const P2& p) { return P2(snap(p.x()), snap(p.y())); }

/// Per-point flag: 0-2 plain, 3 corner, 4 control level L+1, 5 corner with level L. Shrinks to plain.
ControlPoint flagged_point(const P2& p, int flag) {
  ControlPoint cp;
  cp.p = snap(p);
  cp.corner = flag == 3 || flag == 5;
  cp.level = flag == 4 ? 1.0 : flag == 5 ? 0.0 : no_offset;  // offset above the global level, fixed later
  return cp;
}

/// Before the level is known: loops centred at the origin, levels as offsets.
struct Component {
  std::vector<LoopSpec> loops;
  std::string shape;
};

struct RawSpec {
  std::vector<Component> components;
  std::vector<dim2::InteriorControl> interior;  ///< level = offset
  int level = min_generated_level;
};

// Generators are written with rc::gen::exec: every `*gen` is a shrinkable choice, so a
// counterexample shrinks choice by choice (fewer points, radii to the lower bound, no flags).

LoopSpec star_loop(P2 centre, double r_lo, double r_hi, int n_lo, int n_hi, const std::string& name) {
  const int n = *rc::gen::inRange(n_lo, n_hi + 1);
  LoopSpec loop;
  loop.name = name;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * pi * k / n;
    const double r = r_lo + (r_hi - r_lo) * *rc::gen::inRange(0, 21) / 20.0;
    loop.points.push_back(flagged_point(centre + r * P2(std::cos(a), std::sin(a)), *rc::gen::inRange(0, 6)));
  }
  return loop;
}

/// A star-shaped outer loop (radii 0.6-1.0) with 0-3 holes of radius 0.08-0.13 at distance 0.3
/// from the centre (one hole: 0-0.3), spread evenly: clear of each other and of the outer loop.
Component star_component() {
  Component c;
  c.loops.push_back(star_loop(P2::Zero(), 0.6, 1.0, 5, 12, "outer"));
  const int n_holes = *rc::gen::inRange(0, 4);
  const double phase = pi / 6.0 * *rc::gen::inRange(0, 12);
  const double d = n_holes == 1 ? 0.05 * *rc::gen::inRange(0, 7) : 0.3;
  for (int j = 0; j < n_holes; ++j) {
    const double a = phase + 2.0 * pi * j / n_holes;
    c.loops.push_back(star_loop(d * P2(std::cos(a), std::sin(a)), 0.08, 0.13, 4, 8, "hole " + std::to_string(j + 1)));
  }
  c.shape = n_holes == 0 ? "star" : "star+" + std::to_string(n_holes) + " holes";
  return c;
}

/// Not star-shaped: a thick bent polyline ("worm") of 2-5 segments of length 0.5, turning up to
/// 60 degrees at each joint, half-width 0.18-0.3, mitred joints and square ends; scaled to fit
/// a 2 x 2 square around the origin.
Component worm_component() {
  const int m = *rc::gen::inRange(2, 6);
  const double w = 0.18 + 0.03 * *rc::gen::inRange(0, 5);
  std::vector<P2> centre{P2::Zero()};
  double heading = 0.0;
  for (int k = 0; k < m; ++k) {
    if (k > 0) {
      const int t = *rc::gen::inRange(0, 9);  // 0, +15, -15, +30, ... degrees; shrinks to straight
      heading += (t % 2 == 1 ? 1.0 : -1.0) * ((t + 1) / 2) * pi / 12.0;
    }
    centre.push_back(centre.back() + 0.5 * P2(std::cos(heading), std::sin(heading)));
  }
  auto normal = [&](int seg) {
    const P2 d = (centre[std::size_t(seg) + 1] - centre[std::size_t(seg)]).normalized();
    return P2(-d.y(), d.x());
  };
  std::vector<P2> left, right;
  for (int k = 0; k <= m; ++k) {
    P2 off;
    if (k == 0) off = w * normal(0);
    else if (k == m) off = w * normal(m - 1);
    else {
      const P2 a = normal(k - 1), b = normal(k);
      off = w * (a + b) / (1.0 + a.dot(b));  // mitre: at distance w from both offset lines
    }
    left.push_back(centre[std::size_t(k)] + off);
    right.push_back(centre[std::size_t(k)] - off);
  }
  std::vector<P2> poly(right.begin(), right.end());
  poly.insert(poly.end(), left.rbegin(), left.rend());
  Box<2> bb;
  bb.lo = bb.hi = poly[0];
  for (const P2& p : poly) {
    bb.lo = bb.lo.cwiseMin(p);
    bb.hi = bb.hi.cwiseMax(p);
  }
  const double scale = std::min(1.0, 2.0 / (bb.hi - bb.lo).maxCoeff());
  const P2 mid = 0.5 * (bb.lo + bb.hi);
  Component c;
  LoopSpec loop;
  loop.name = "worm";
  for (const P2& p : poly) loop.points.push_back(flagged_point(scale * (p - mid), *rc::gen::inRange(0, 6)));
  c.loops.push_back(loop);
  c.shape = "worm" + std::to_string(m);
  return c;
}

/// Offsets (ControlPoint::level, InteriorControl::level) become absolute levels above `level`.
DomainSpec place(const RawSpec& raw, int level) {
  DomainSpec spec;
  spec.level = level;
  for (std::size_t j = 0; j < raw.components.size(); ++j) {
    const P2 shift(2.5 * double(j), 0.0);
    for (LoopSpec loop : raw.components[j].loops) {
      if (raw.components.size() > 1) loop.name = "c" + std::to_string(j + 1) + " " + loop.name;
      for (ControlPoint& cp : loop.points) {
        cp.p = snap(cp.p + shift);
        cp.level = cp.level == no_offset ? dim2::no_level : level + cp.level;
      }
      spec.loops.push_back(loop);
    }
    spec.shape += (j > 0 ? ", " : "") + raw.components[j].shape;
  }
  for (dim2::InteriorControl ic : raw.interior) {
    ic.level += level;
    spec.interior.push_back(ic);
  }
  return spec;
}

/// The spec at the level its features need, or nothing when the loops meet (check_domain) or
/// the features need a level above max_generated_level.
std::optional<DomainSpec> finish(const RawSpec& raw) {
  DomainSpec spec = place(raw, raw.level);
  int need = 0;
  try {
    need = level_for_features(to_domain(spec));
  } catch (const InputError&) {
    return std::nullopt;
  }
  if (need > max_generated_level) return std::nullopt;
  if (need > spec.level) spec = place(raw, need);
  return spec;
}

RawSpec raw_spec() {
  RawSpec raw;
  const int n_components = *rc::gen::inRange(1, 3);
  for (int j = 0; j < n_components; ++j)
    raw.components.push_back(*rc::gen::inRange(0, 2) == 0 ? star_component() : worm_component());
  const int n_interior = *rc::gen::inRange(0, 3);
  for (int k = 0; k < n_interior; ++k) {
    dim2::InteriorControl ic;
    ic.p = P2(snap(-0.5 + 0.1 * *rc::gen::inRange(0, 11)), snap(-0.5 + 0.1 * *rc::gen::inRange(0, 11)));
    ic.radius = 0.1 * *rc::gen::inRange(0, 4);
    ic.level = 1.0;
    raw.interior.push_back(ic);
  }
  raw.level = *rc::gen::inRange(min_generated_level, 9);
  return raw;
}

void append_number(std::string& out, double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

}  // namespace

dim2::Domain to_domain(const DomainSpec& spec) {
  dim2::Domain d;
  for (const LoopSpec& l : spec.loops) d.loops.push_back(dim2::loop_from_bspline(l.points, l.name));
  d.interior = spec.interior;
  d.default_level = spec.level;
  d.source = "generated";
  return d;
}

std::string to_native_json(const DomainSpec& spec, dim2::ElementKind elements) {
  std::string s = "{\n  \"comment\": \"generated by tests/dim2/domain_generators: " + spec.shape + "\",\n  \"loops\": [";
  for (std::size_t i = 0; i < spec.loops.size(); ++i) {
    s += i ? ",\n" : "\n";
    s += "    {\"name\": \"" + spec.loops[i].name + "\", \"points\": [";
    const auto& pts = spec.loops[i].points;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      s += k ? ",\n      " : "\n      ";
      s += "{\"x\": ";
      append_number(s, pts[k].p.x());
      s += ", \"y\": ";
      append_number(s, pts[k].p.y());
      if (pts[k].corner) s += ", \"corner\": true";
      if (pts[k].level != dim2::no_level) {
        s += ", \"level\": ";
        append_number(s, pts[k].level);
      }
      s += "}";
    }
    s += "]}";
  }
  s += "\n  ]";
  if (!spec.interior.empty()) {
    s += ",\n  \"interior\": [";
    for (std::size_t k = 0; k < spec.interior.size(); ++k) {
      const auto& ic = spec.interior[k];
      s += k ? ", " : "";
      s += "{\"x\": ";
      append_number(s, ic.p.x());
      s += ", \"y\": ";
      append_number(s, ic.p.y());
      s += ", \"level\": ";
      append_number(s, ic.level);
      s += ", \"radius\": ";
      append_number(s, ic.radius);
      s += "}";
    }
    s += "]";
  }
  s += ",\n  \"options\": {\"level\": " + std::to_string(spec.level) + ", \"elements\": \"" + dim2::name(elements) +
       "\"}\n}\n";
  return s;
}

dim2::Options2d to_options(const PipelineCase& c) {
  dim2::Options2d opt;
  opt.level = c.domain.level;
  opt.elements = c.elements;
  opt.smoothing_iterations = c.smoothing_iterations;
  opt.buffer = c.buffer;
  opt.keep_stages = false;
  return opt;
}

double min_feature_size(const dim2::Domain& domain) {
  struct Sample {
    P2 p;
    double s;  // arc length from the loop's start (polyline)
    int loop;
  };
  constexpr int per_piece = 12;
  std::vector<Sample> samples;
  std::vector<double> length;
  for (std::size_t i = 0; i < domain.loops.size(); ++i) {
    double s = 0.0;
    P2 prev = domain.loops[i].pieces[0][0];
    for (const dim2::Bezier& q : domain.loops[i].pieces)
      for (int k = 0; k < per_piece; ++k) {
        const P2 p = dim2::bezier_point(q, double(k) / per_piece);
        s += (p - prev).norm();
        samples.push_back({p, s, int(i)});
        prev = p;
      }
    length.push_back(s + (domain.loops[i].pieces[0][0] - prev).norm());
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t a = 0; a < samples.size(); ++a)
    for (std::size_t b = a + 1; b < samples.size(); ++b) {
      const double d = (samples[a].p - samples[b].p).norm();
      if (d >= best) continue;
      if (samples[a].loop == samples[b].loop) {
        const double ds = std::abs(samples[a].s - samples[b].s);
        const double arc = std::min(ds, length[std::size_t(samples[a].loop)] - ds);
        if (d >= arc / 4.0) continue;
      }
      best = d;
    }
  return best;
}

double root_side(const dim2::Domain& domain) {
  const Box<2> root = dim2::CurveBoundary(domain).root_box();
  return (root.hi - root.lo).maxCoeff();
}

int level_for_features(const dim2::Domain& domain) {
  const double side = root_side(domain);  // first: CurveBoundary refuses invalid domains
  const double thin = min_feature_size(domain);
  return std::max(0, int(std::ceil(std::log2(side * min_feature_cells / thin))));
}

rc::Gen<DomainSpec> gen_domain_spec() {
  return rc::gen::map(rc::gen::suchThat(rc::gen::map(rc::gen::exec(raw_spec), finish),
                                        [](const std::optional<DomainSpec>& s) { return s.has_value(); }),
                      [](const std::optional<DomainSpec>& s) { return *s; });
}

rc::Gen<PipelineCase> gen_pipeline_case(dim2::ElementKind elements) {
  return rc::gen::exec([elements] {
    PipelineCase c;
    c.domain = *gen_domain_spec();
    c.elements = elements;
    c.smoothing_iterations = 4 - *rc::gen::inRange(0, 5);  // shrinks to the default, 4
    c.buffer = 0.05 * *rc::gen::inRange(0, 11);
    return c;
  });
}

rc::Gen<PipelineCase> gen_pipeline_case() {
  return rc::gen::mapcat(rc::gen::element(dim2::ElementKind::Tri, dim2::ElementKind::Mixed, dim2::ElementKind::Quad),
                         [](dim2::ElementKind k) { return gen_pipeline_case(k); });
}

std::string to_native_json(const PipelineCase& c) {
  std::string s = to_native_json(c.domain, c.elements);
  std::string extra = ",\n  \"_pipeline\": {\"smoothing_iterations\": " + std::to_string(c.smoothing_iterations) +
                      ", \"buffer\": ";
  append_number(extra, c.buffer);
  extra += "}\n}\n";
  s.replace(s.rfind("\n}\n"), 3, extra);
  return s;
}

void showValue(const DomainSpec& spec, std::ostream& os) { os << to_native_json(spec, dim2::ElementKind::Tri); }

void showValue(const PipelineCase& c, std::ostream& os) {
  os << "elements " << dim2::name(c.elements) << ", smoothing " << c.smoothing_iterations << ", buffer " << c.buffer
     << ", level " << c.domain.level << " (" << c.domain.shape << "); native file:\n"
     << to_native_json(c);
}

}  // namespace febemesh::test
