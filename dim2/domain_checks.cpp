#include "dim2/domain_checks.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "dim2/bezier.hpp"
#include "dim2/loop_geometry.hpp"

namespace febemesh::dim2 {

namespace {

std::string coords(const P2& p) {
  std::ostringstream os;
  os.precision(12);
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

/// A part of a loop that is monotone in x and y (so it cannot meet itself).
struct Segment {
  Bezier q;
  Box<2> box;
  std::size_t index = 0;  ///< position along its loop
};

std::vector<Segment> monotone_segments(const Loop& loop) {
  std::vector<Segment> out;
  for (const Bezier& q : loop.pieces) {
    double cuts[4];
    const int n = bezier_extrema(q, cuts);
    double u0 = 0.0;
    Bezier rest = q;
    for (int k = 0; k <= n; ++k) {
      const double u1 = k < n ? cuts[k] : 1.0;
      if (k < n && (u1 - u0 <= 1e-6 || 1.0 - u1 <= 1e-6)) continue;  // a sliver this short cannot hold a crossing
      Bezier part = rest;
      if (k < n) {
        auto [l, r] = bezier_split(rest, (u1 - u0) / (1.0 - u0));
        part = l;
        rest = r;
        u0 = u1;
      }
      out.push_back(Segment{part, bezier_control_box(part), out.size()});
    }
  }
  return out;
}

/// Do the parts of a (ending at junction J) and b (starting at J) lie in opposite open
/// half-planes through J? Then they meet only at J.
bool separated_at_junction(const Bezier& a, const Bezier& b) {
  const P2 j = a[3];
  P2 da = P2::Zero(), db = P2::Zero();
  for (int k = 0; k < 3; ++k)
    if (a[k] != j) da += (a[k] - j).normalized();
  for (int k = 1; k < 4; ++k)
    if (b[k] != j) db += (b[k] - j).normalized();
  if (da == P2::Zero() || db == P2::Zero()) return false;
  const P2 n = da.normalized() - db.normalized();
  for (int k = 0; k < 3; ++k)
    if (a[k] != j && !((a[k] - j).dot(n) > 0.0)) return false;
  for (int k = 1; k < 4; ++k)
    if (b[k] != j && !((b[k] - j).dot(n) < 0.0)) return false;
  return true;
}

/// Whether the control points of b lie more than tol to one side of the band that a's control
/// points span across a's chord (the fat line of Bezier clipping, Sederberg & Nishita 1990):
/// each curve lies in its control points' hull, so the curves are then more than tol apart.
bool beyond_fat_line(const Bezier& a, const Bezier& b, double tol) {
  const P2 d = a[3] - a[0];
  const double len = d.norm();
  if (!(len > 0.0)) return false;
  const P2 n(-d.y() / len, d.x() / len);
  double alo = 0.0, ahi = 0.0, blo = n.dot(b[0] - a[0]), bhi = blo;
  for (int k = 1; k < 3; ++k) alo = std::min(alo, n.dot(a[k] - a[0])), ahi = std::max(ahi, n.dot(a[k] - a[0]));
  for (int k = 1; k < 4; ++k) blo = std::min(blo, n.dot(b[k] - a[0])), bhi = std::max(bhi, n.dot(b[k] - a[0]));
  return blo > ahi + tol || bhi < alo - tol;
}

/// Bezier-Bezier meeting by subdivision. ab: a's end is b's start (a junction of the loop,
/// not an intersection); ba: b's end is a's start. Pieces are dropped when their control boxes
/// or their fat lines are more than tol apart: boxes alone separate two long, nearly parallel
/// pieces that lean only after about length / gap subdivisions (a fuzzed .poly spike 7.8e9 long
/// and 11 wide took 1.8 s in a release build, over 10 s under the sanitizers; its whole mesh2d
/// run now takes 13 ms).
std::optional<P2> meet(const Bezier& a, const Bezier& b, bool ab, bool ba, double tol, int depth) {
  const Box<2> ca = bezier_control_box(a), cb = bezier_control_box(b);
  const P2 gap = (cb.lo - ca.hi).cwiseMax(ca.lo - cb.hi);
  if (gap.maxCoeff() > tol) return std::nullopt;
  if (beyond_fat_line(a, b, tol) || beyond_fat_line(b, a, tol)) return std::nullopt;
  if (ab && !ba && separated_at_junction(a, b)) return std::nullopt;
  if (ba && !ab && separated_at_junction(b, a)) return std::nullopt;
  const double sa = ca.extent().maxCoeff(), sb = cb.extent().maxCoeff();
  if (std::max(sa, sb) <= tol || depth == 0) return P2(0.5 * (bezier_point(a, 0.5) + bezier_point(b, 0.5)));
  if (sa >= sb) {
    const auto [a1, a2] = bezier_split(a, 0.5);
    if (auto p = meet(a1, b, false, ba, tol, depth - 1)) return p;
    return meet(a2, b, ab, false, tol, depth - 1);
  }
  const auto [b1, b2] = bezier_split(b, 0.5);
  if (auto p = meet(a, b1, ab, false, tol, depth - 1)) return p;
  return meet(a, b2, false, ba, tol, depth - 1);
}

/// Pairs of segments (one from each list) whose boxes come within tol, by a sweep in x.
template <typename Visit>
std::optional<P2> sweep_pairs(const std::vector<Segment>& s, const std::vector<Segment>* t, double tol, Visit visit) {
  struct Item { double lo, hi; int list; std::size_t k; };
  std::vector<Item> items;
  for (std::size_t k = 0; k < s.size(); ++k) items.push_back({s[k].box.lo.x(), s[k].box.hi.x(), 0, k});
  if (t)
    for (std::size_t k = 0; k < t->size(); ++k) items.push_back({(*t)[k].box.lo.x(), (*t)[k].box.hi.x(), 1, k});
  std::sort(items.begin(), items.end(), [](const Item& x, const Item& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.list != y.list ? x.list < y.list : x.k < y.k);
  });
  for (std::size_t i = 0; i < items.size(); ++i)
    for (std::size_t j = i + 1; j < items.size() && items[j].lo <= items[i].hi + tol; ++j) {
      if (t && items[i].list == items[j].list) continue;
      const Segment& x = items[i].list == 0 ? s[items[i].k] : (*t)[items[i].k];
      const Segment& y = items[j].list == 0 ? s[items[j].k] : (*t)[items[j].k];
      const P2 gap = (y.box.lo - x.box.hi).cwiseMax(x.box.lo - y.box.hi);
      if (gap.maxCoeff() > tol) continue;
      if (auto p = visit(x, y)) return p;
    }
  return std::nullopt;
}

}  // namespace

std::optional<P2> loop_self_intersection(const Loop& loop, double tol) {
  const std::vector<Segment> segs = monotone_segments(loop);
  const std::size_t m = segs.size();
  return sweep_pairs(segs, nullptr, tol, [&](const Segment& x, const Segment& y) -> std::optional<P2> {
    const Segment& a = x.index < y.index ? x : y;
    const Segment& b = x.index < y.index ? y : x;
    const bool ab = b.index == a.index + 1;
    const bool ba = a.index == 0 && b.index == m - 1;
    return meet(a.q, b.q, ab, ba, tol, 200);
  });
}

std::optional<P2> loops_intersection(const Loop& a, const Loop& b, double tol) {
  const std::vector<Segment> sa = monotone_segments(a), sb = monotone_segments(b);
  return sweep_pairs(sa, &sb, tol, [&](const Segment& x, const Segment& y) { return meet(x.q, y.q, false, false, tol, 200); });
}

std::optional<LoopsMeeting> first_loops_intersection(const std::vector<Loop>& loops, double tol) {
  std::vector<Box<2>> boxes;
  boxes.reserve(loops.size());
  for (const Loop& l : loops) boxes.push_back(bounding_box(l));
  for (std::size_t i = 0; i < loops.size(); ++i)
    for (std::size_t j = i + 1; j < loops.size(); ++j) {
      const P2 gap = (boxes[j].lo - boxes[i].hi).cwiseMax(boxes[i].lo - boxes[j].hi);
      if (gap.maxCoeff() > tol) continue;
      if (const std::optional<P2> p = loops_intersection(loops[i], loops[j], tol)) return LoopsMeeting{i, j, *p};
    }
  return std::nullopt;
}

std::optional<P2> polyline_intersection_ref(const Loop& a, const Loop* b, int samples) {
  auto poly = [&](const Loop& l) {
    std::vector<P2> v;
    for (const Bezier& q : l.pieces)
      for (int k = 0; k < samples; ++k) v.push_back(bezier_point(q, double(k) / samples));
    return v;
  };
  const std::vector<P2> pa = poly(a), pb = b ? poly(*b) : pa;
  const std::size_t na = pa.size(), nb = pb.size();
  for (std::size_t i = 0; i < na; ++i)
    for (std::size_t j = b ? 0 : i + 2; j < nb; ++j) {
      if (!b && i == 0 && j == nb - 1) continue;
      const P2 p = pa[i], r = pa[(i + 1) % na] - p, q = pb[j], s = pb[(j + 1) % nb] - q;
      const double den = cross(r, s);
      if (den == 0.0) continue;
      const double t = cross(q - p, s) / den, u = cross(q - p, r) / den;
      if (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0) return P2(p + t * r);
    }
  return std::nullopt;
}

std::vector<int> nesting_depths(const std::vector<Loop>& loops) {
  std::vector<int> depth(loops.size(), 0);
  for (std::size_t i = 0; i < loops.size(); ++i)
    for (std::size_t j = 0; j < loops.size(); ++j)
      if (i != j && !loops[i].pieces.empty() && winding_number(loops[j], loops[i].pieces[0][0]) != 0) ++depth[i];
  return depth;
}

double check_tolerance(const Box<2>& box) { return 1e-10 * box.extent().maxCoeff(); }

double check_tolerance(const Domain& domain) {
  Box<2> box = Box<2>::empty();
  for (const Loop& l : domain.loops)
    for (const Bezier& q : l.pieces)
      for (const P2& p : q) box.expand(p);
  return domain.loops.empty() ? 0.0 : check_tolerance(box);
}

void check_domain(const Domain& domain) {
  const std::string src = domain.source.empty() ? std::string("input") : domain.source;
  if (domain.loops.empty()) throw InputError(src + ": no geometry (no closed loop found)");
  for (const Loop& l : domain.loops)
    for (const Bezier& q : l.pieces)
      for (const P2& p : q)
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
          throw InputError(src + ": loop '" + l.name + "' has a non-finite point " + coords(p));
  const double tol = check_tolerance(domain);
  auto zero_area = [&](const Loop& l) {
    const Box<2> box = bounding_box(l);
    return InputError(src + ": loop '" + l.name + "' encloses zero area (it lies within " + coords(box.lo) + " - " +
                      coords(box.hi) + ")");
  };
  for (const Loop& l : domain.loops) {
    if (l.pieces.empty()) throw InputError(src + ": loop '" + l.name + "' is degenerate (it has no extent)");
    // A flat loop (all control points on one line) is reported as such, not as overlapping itself.
    const P2 o = l.pieces[0][0];
    P2 far = o;
    for (const Bezier& q : l.pieces)
      for (const P2& p : q)
        if ((p - o).norm() > (far - o).norm()) far = p;
    const double size = (far - o).norm();
    double off_line = 0.0;
    for (const Bezier& q : l.pieces)
      for (const P2& p : q) off_line = std::max(off_line, std::abs(cross(far - o, p - o)));
    if (!(size > tol) || off_line <= 1e-12 * size * size) throw zero_area(l);
  }
  for (const Loop& l : domain.loops)
    if (auto p = loop_self_intersection(l, tol))
      throw InputError(src + ": loop '" + l.name + "' intersects itself at " + coords(*p));
  for (const Loop& l : domain.loops) {
    const double size = bounding_box(l).extent().norm();
    if (std::abs(signed_area(l)) <= 1e-12 * size * size) throw zero_area(l);
  }
  if (const std::optional<LoopsMeeting> m = first_loops_intersection(domain.loops, tol))
    throw InputError(src + ": loops '" + domain.loops[m->i].name + "' and '" + domain.loops[m->j].name + "' intersect at " +
                     coords(m->at));
  for (const InteriorControl& c : domain.interior)
    if (!std::isfinite(c.p.x()) || !std::isfinite(c.p.y()) || !std::isfinite(c.level) || !(c.radius >= 0.0))
      throw InputError(src + ": interior control point at " + coords(c.p) + " has a non-finite position, level or radius");
}

}  // namespace febemesh::dim2
