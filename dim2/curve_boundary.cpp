#include "dim2/curve_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/sized_level.hpp"
#include "dim2/domain_checks.hpp"
#include "dim2/loop_geometry.hpp"

namespace febemesh::dim2 {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

double box_distance2(const Box<2>& b, const P2& p) {
  const P2 d = (b.lo - p).cwiseMax(p - b.hi).cwiseMax(0.0);
  return d.squaredNorm();
}

/// Bernstein coefficients (degree 6) of f(u) = |P(u) - p|^2 on [0, 1]: min of them is a lower
/// bound of f, the end ones are exact values, their differences give the sign of f'.
void distance_coefficients(const Bezier& q, const P2& p, double c[7]) {
  const P2 d0 = q[0] - p, d1 = q[1] - p, d2 = q[2] - p, d3 = q[3] - p;
  c[0] = d0.dot(d0);
  c[1] = d0.dot(d1);
  c[2] = (2.0 * d0.dot(d2) + 3.0 * d1.dot(d1)) / 5.0;
  c[3] = (d0.dot(d3) + 9.0 * d1.dot(d2)) / 10.0;
  c[4] = (2.0 * d1.dot(d3) + 3.0 * d2.dot(d2)) / 5.0;
  c[5] = d2.dot(d3);
  c[6] = d3.dot(d3);
}

void split_coefficients(const double c[7], double l[7], double r[7]) {
  double w[7];
  std::copy(c, c + 7, w);
  l[0] = w[0];
  r[6] = w[6];
  for (int k = 1; k < 7; ++k) {
    for (int i = 0; i < 7 - k; ++i) w[i] = 0.5 * (w[i] + w[i + 1]);
    l[k] = w[0];
    r[6 - k] = w[6 - k];
  }
}

/// Sign pattern of f' on an interval: 0 = monotone, 1 = one interior minimum (down then up),
/// 2 = one interior maximum, 3 = unknown (more variations).
int derivative_pattern(const double c[7]) {
  int variations = 0, first = 0, last = 0;
  for (int k = 0; k < 6; ++k) {
    const double e = c[k + 1] - c[k];
    const int s = e > 0.0 ? 1 : (e < 0.0 ? -1 : 0);
    if (s == 0) continue;
    if (first == 0) first = s;
    else if (s != last) ++variations;
    last = s;
  }
  if (variations == 0) return 0;
  if (variations == 1) return first < 0 ? 1 : 2;
  return 3;
}

/// Safeguarded Newton (bisection fallback) for g(u) = (P(u) - p) . P'(u) = 0 in [lo, hi], where
/// g goes from negative to positive (a minimum of the distance).
double newton_minimum(const CubicPoly& poly, const P2& p, double lo, double hi) {
  double u = 0.5 * (lo + hi);
  for (int it = 0; it < 60; ++it) {
    const P2 d = poly.point(u) - p, t = poly.d1(u), s = poly.d2(u);
    const double g = d.dot(t), gp = t.dot(t) + d.dot(s);
    if (g < 0.0) lo = u;
    else if (g > 0.0) hi = u;
    else return u;
    double next = gp > 0.0 ? u - g / gp : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - u) <= 2e-16 || hi - lo <= 2e-16) return next;
    u = next;
  }
  return u;
}

bool boxes_meet(const Box<2>& a, const Box<2>& b) { return a.overlaps(b); }

bool curve_meets_box(const Bezier& q, const Box<2>& box, double tiny, int depth) {
  const Box<2> cb = bezier_control_box(q);
  if (!boxes_meet(cb, box)) return false;
  if (box.contains(q[0]) || box.contains(q[3])) return true;
  if (depth == 0 || cb.extent().maxCoeff() <= tiny) return true;  // conservative: PARTIAL
  const auto [l, r] = bezier_split(q, 0.5);
  return curve_meets_box(l, box, tiny, depth - 1) || curve_meets_box(r, box, tiny, depth - 1);
}

/// Parameter range [lo, hi] (within [u0, u1]) of the parts of q that meet the box.
void meeting_range(const Bezier& q, const Box<2>& box, double u0, double u1, double tiny, int depth, double& lo,
                   double& hi) {
  const Box<2> cb = bezier_control_box(q);
  if (!boxes_meet(cb, box)) return;
  const bool inside = box.contains(cb.lo) && box.contains(cb.hi);
  if (inside || depth == 0 || cb.extent().maxCoeff() <= tiny) {
    lo = std::min(lo, u0);
    hi = std::max(hi, u1);
    return;
  }
  const double m = 0.5 * (u0 + u1);
  const auto [l, r] = bezier_split(q, 0.5);
  meeting_range(l, box, u0, m, tiny, depth - 1, lo, hi);
  meeting_range(r, box, m, u1, tiny, depth - 1, lo, hi);
}

bool curve_hits_segment(const Bezier& q, const P2& a, const P2& d, double len2, double s_lo, double s_hi, double tiny,
                        int depth) {
  const P2 n(-d.y(), d.x());
  int above = 0, below = 0, before = 0, after = 0;
  for (const P2& c : q) {
    const double s = n.dot(c - a);
    above += s > 0.0;
    below += s < 0.0;
    const double w = d.dot(c - a) / len2;
    before += w < s_lo;
    after += w > s_hi;
  }
  if (above == 4 || below == 4 || before == 4 || after == 4) return false;
  if (depth == 0 || bezier_control_box(q).extent().maxCoeff() <= tiny) return true;
  const auto [l, r] = bezier_split(q, 0.5);
  return curve_hits_segment(l, a, d, len2, s_lo, s_hi, tiny, depth - 1) ||
         curve_hits_segment(r, a, d, len2, s_lo, s_hi, tiny, depth - 1);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Construction

CurveBoundary::CurveBoundary(Domain domain) : domain_(std::move(domain)) {
  check_domain(domain_);
  std::vector<Loop>& loops = domain_.loops;
  const std::size_t nl = loops.size();
  depth_ = nesting_depths(loops);
  hole_.resize(nl);
  for (std::size_t i = 0; i < nl; ++i) {
    hole_[i] = depth_[i] % 2 == 1;
    const bool ccw = dim2::signed_area(loops[i]) > 0.0;
    if (ccw == bool(hole_[i])) loops[i] = reversed(loops[i]);
    signed_area_.push_back(dim2::signed_area(loops[i]));
    length_.push_back(dim2::length(loops[i]));
  }
  bbox_ = Box<2>::empty();
  for (const Loop& l : loops) {
    const Box<2> b = dim2::bounding_box(l);
    bbox_.expand(b.lo);
    bbox_.expand(b.hi);
  }
  scale_ = std::max(bbox_.extent().maxCoeff(), std::numeric_limits<double>::min());

  for (std::size_t i = 0; i < nl; ++i)
    for (std::size_t k = 0; k < loops[i].n_pieces(); ++k) {
      const Bezier& q = loops[i].pieces[k];
      pieces_.push_back(Piece{q, CubicPoly(q), bezier_control_box(q), std::int32_t(i), std::int32_t(k)});
    }
  nodes_.reserve(2 * pieces_.size());
  build_bvh(0, int(pieces_.size()));
  build_ray_bands();
  rec_of_.resize(nl);
  for (std::size_t i = 0; i < nl; ++i) rec_of_[i].assign(loops[i].n_pieces(), -1);
  for (std::size_t r = 0; r < pieces_.size(); ++r)
    rec_of_[std::size_t(pieces_[r].loop)][std::size_t(pieces_[r].index)] = int(r);

  corner_of_.resize(nl);
  level_junctions_.resize(nl);
  for (std::size_t i = 0; i < nl; ++i) {
    const Loop& l = loops[i];
    const std::size_t n = l.n_pieces();
    corner_of_[i].assign(n, -1);
    for (std::size_t k = 0; k < n; ++k) {
      if (l.level[k] != no_level) {
        level_junctions_[i].push_back(int(k));
        has_curve_levels_ = true;
      }
      if (!l.corner[k]) continue;
      const P2 in = bezier_end_direction(l.pieces[(k + n - 1) % n]);
      const P2 out = bezier_start_direction(l.pieces[k]);
      // The solid is on the left: a left turn by theta leaves an interior angle 180 - theta.
      const double turn = std::atan2(cross(in, out), in.dot(out)) * 180.0 / M_PI;
      corner_of_[i][k] = int(corners_.size());
      corners_.push_back(CurveCorner{int(i), double(k), l.pieces[k][0], 180.0 - turn});
    }
  }
  compute_automatic_levels();
}

int CurveBoundary::build_bvh(int first, int last) {
  const int id = int(nodes_.size());
  nodes_.push_back(Node{});
  Box<2> box = Box<2>::empty(), centres = Box<2>::empty();
  for (int r = first; r < last; ++r) {
    box.expand(pieces_[std::size_t(r)].box.lo);
    box.expand(pieces_[std::size_t(r)].box.hi);
    centres.expand(pieces_[std::size_t(r)].box.center());
  }
  nodes_[std::size_t(id)].box = box;
  if (last - first <= 2) {
    nodes_[std::size_t(id)].first = first;
    nodes_[std::size_t(id)].count = last - first;
    return id;
  }
  const int axis = centres.extent().x() >= centres.extent().y() ? 0 : 1;
  const int mid = (first + last) / 2;
  std::nth_element(pieces_.begin() + first, pieces_.begin() + mid, pieces_.begin() + last,
                   [axis](const Piece& a, const Piece& b) {
                     const double ca = a.box.lo[axis] + a.box.hi[axis], cb = b.box.lo[axis] + b.box.hi[axis];
                     return ca != cb ? ca < cb : (a.loop != b.loop ? a.loop < b.loop : a.index < b.index);
                   });
  const int left = build_bvh(first, mid);
  const int right = build_bvh(mid, last);
  nodes_[std::size_t(id)].left = left;
  nodes_[std::size_t(id)].right = right;
  return id;
}

template <typename NodeTest, typename LeafVisit>
void CurveBoundary::traverse(NodeTest&& test, LeafVisit&& visit) const {
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& nd = nodes_[std::size_t(stack[--top])];
    if (!test(nd.box)) continue;
    if (nd.left < 0) {
      for (int r = nd.first; r < nd.first + nd.count; ++r) visit(r);
    } else {
      stack[top++] = nd.right;
      stack[top++] = nd.left;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Closest points

void CurveBoundary::piece_minimum(int rec, const P2& p, double& best_d2, int& best_rec, double& best_u) const {
  const Piece& pc = pieces_[std::size_t(rec)];
  struct Item { double c[7]; double u0, u1; int depth; };
  Item stack[64];
  int top = 0;
  distance_coefficients(pc.q, p, stack[0].c);
  stack[0].u0 = 0.0;
  stack[0].u1 = 1.0;
  stack[0].depth = 0;
  top = 1;
  while (top > 0) {
    const Item it = stack[--top];
    const double lower = *std::min_element(it.c, it.c + 7);
    if (lower >= best_d2) continue;
    // End coefficients are exact values of f.
    if (it.c[0] < best_d2) { best_d2 = it.c[0]; best_rec = rec; best_u = it.u0; }
    if (it.c[6] < best_d2) { best_d2 = it.c[6]; best_rec = rec; best_u = it.u1; }
    const int pattern = derivative_pattern(it.c);
    if (pattern == 0 || pattern == 2) continue;
    if (pattern == 1 || it.depth >= 40 || top >= 62) {
      const double u = newton_minimum(pc.poly, p, it.u0, it.u1);
      const double d2 = (pc.poly.point(u) - p).squaredNorm();
      if (d2 < best_d2) { best_d2 = d2; best_rec = rec; best_u = u; }
      continue;
    }
    Item l, r;
    split_coefficients(it.c, l.c, r.c);
    const double m = 0.5 * (it.u0 + it.u1);
    l.u0 = it.u0; l.u1 = m; r.u0 = m; r.u1 = it.u1;
    l.depth = r.depth = it.depth + 1;
    // Nearer half on top of the stack.
    const double ll = *std::min_element(l.c, l.c + 7), rl = *std::min_element(r.c, r.c + 7);
    if (ll <= rl) { stack[top++] = r; stack[top++] = l; }
    else { stack[top++] = l; stack[top++] = r; }
  }
}

ClosestPoint<2> CurveBoundary::make_result(int rec, double u, const P2& p) const {
  const Piece& pc = pieces_[std::size_t(rec)];
  const Loop& loop = domain_.loops[std::size_t(pc.loop)];
  const std::size_t n = loop.n_pieces();
  std::size_t piece = std::size_t(pc.index);
  // Within round-off of a corner is the corner. Newton's minimum can end just short of a
  // piece's end, which then is not reported as the corner; where the curve is stationary at the
  // corner (a repeated control point) u = 1 - 2.6e-9 was 3e-28 from it, and a node the quality
  // pass slid there sat on the corner's node (a random domain of the property suite: quad, 2
  // smoothing iterations, a hole's tip at (0.19, 0)). So: within 1e-12 of the bounding box's
  // diagonal (the validator's duplicate-node distance) of a corner, the corner.
  const std::size_t next = (piece + 1) % n;
  if (u > 0.0 && u < 1.0) {
    const double tol = 1e-12 * bbox_.extent().norm();
    const P2 at_u = bezier_point(pc.q, u);
    if (corner_of_[std::size_t(pc.loop)][piece] >= 0 && (at_u - bezier_point(pc.q, 0.0)).norm() <= tol) u = 0.0;
    else if (corner_of_[std::size_t(pc.loop)][next] >= 0 && (at_u - bezier_point(pc.q, 1.0)).norm() <= tol) u = 1.0;
  }
  const P2 point = bezier_point(pc.q, u);
  if (u >= 1.0) {
    piece = next;
    u = 0.0;
  }
  ClosestPoint<2> r;
  r.point = point;
  r.distance = (point - p).norm();
  r.where.patch = pc.loop;
  r.where.param[0] = double(piece) + u;
  if (u == 0.0 && corner_of_[std::size_t(pc.loop)][piece] >= 0) {
    r.where.kind = BoundaryLocation::Kind::Corner;
    r.where.feature = corner_of_[std::size_t(pc.loop)][piece];
  }
  return r;
}

ClosestPoint<2> CurveBoundary::closest_point(const P2& p) const {
  double best_d2 = inf, best_u = 0.0;
  int best_rec = 0;
  if (nodes_.empty()) return {};
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& nd = nodes_[std::size_t(stack[--top])];
    if (box_distance2(nd.box, p) >= best_d2) continue;
    if (nd.left < 0) {
      for (int r = nd.first; r < nd.first + nd.count; ++r)
        if (box_distance2(pieces_[std::size_t(r)].box, p) < best_d2) piece_minimum(r, p, best_d2, best_rec, best_u);
      continue;
    }
    const double dl = box_distance2(nodes_[std::size_t(nd.left)].box, p);
    const double dr = box_distance2(nodes_[std::size_t(nd.right)].box, p);
    if (dl <= dr) { stack[top++] = nd.right; stack[top++] = nd.left; }
    else { stack[top++] = nd.left; stack[top++] = nd.right; }
  }
  return make_result(best_rec, best_u, p);
}

void CurveBoundary::piece_local_minima(int rec, const P2& p, double bound_d2, std::vector<Candidate>& out) const {
  const Piece& pc = pieces_[std::size_t(rec)];
  struct Item { double c[7]; double u0, u1; int depth; };
  std::vector<Item> stack(1);
  distance_coefficients(pc.q, p, stack[0].c);
  stack[0].u0 = 0.0;
  stack[0].u1 = 1.0;
  stack[0].depth = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (*std::min_element(it.c, it.c + 7) >= bound_d2) continue;
    const int pattern = derivative_pattern(it.c);
    if (pattern == 0 || pattern == 2) continue;
    if (pattern == 1 || it.depth >= 40) {
      const double u = newton_minimum(pc.poly, p, it.u0, it.u1);
      // Minima at the ends of the piece are junction minima (junction_minima finds them).
      if (u > 1e-12 && u < 1.0 - 1e-12) out.push_back({(pc.poly.point(u) - p).squaredNorm(), rec, u});
      continue;
    }
    Item l, r;
    split_coefficients(it.c, l.c, r.c);
    const double m = 0.5 * (it.u0 + it.u1);
    l.u0 = it.u0; l.u1 = m; r.u0 = m; r.u1 = it.u1;
    l.depth = r.depth = it.depth + 1;
    stack.push_back(r);
    stack.push_back(l);
  }
}

void CurveBoundary::junction_minima(int rec, const P2& p, std::vector<Candidate>& out) const {
  // The junction at the start of this piece: the distance falls into it and rises out of it.
  const Piece& pc = pieces_[std::size_t(rec)];
  const Loop& loop = domain_.loops[std::size_t(pc.loop)];
  const std::size_t n = loop.n_pieces();
  const Bezier& prev = loop.pieces[(std::size_t(pc.index) + n - 1) % n];
  const P2 v = pc.q[0] - p;
  const P2 dir_in = bezier_end_direction(prev), dir_out = bezier_start_direction(pc.q);
  // A minimum exactly at a smooth junction has both products zero up to rounding.
  const double tol = 1e-12 * v.norm();
  if (v.dot(dir_in) <= tol * dir_in.norm() && v.dot(dir_out) >= -tol * dir_out.norm())
    out.push_back({v.squaredNorm(), rec, 0.0});
}

std::vector<ClosestPoint<2>> CurveBoundary::closest_points(const P2& p, int max_count) const {
  std::vector<ClosestPoint<2>> result;
  if (max_count <= 0 || pieces_.empty()) return result;
  result.push_back(closest_point(p));
  std::vector<Candidate> cands;
  for (int r = 0; r < int(pieces_.size()); ++r) {
    piece_local_minima(r, p, inf, cands);
    junction_minima(r, p, cands);
  }
  std::vector<ClosestPoint<2>> all;
  for (const Candidate& c : cands) all.push_back(make_result(c.rec, c.u, p));
  std::sort(all.begin(), all.end(), [](const ClosestPoint<2>& a, const ClosestPoint<2>& b) {
    if (a.distance != b.distance) return a.distance < b.distance;
    if (a.where.patch != b.where.patch) return a.where.patch < b.where.patch;
    return a.where.param[0] < b.where.param[0];
  });
  // Drop duplicates (a minimum found both as a piece end and a junction, or equal to the first).
  auto same = [&](const ClosestPoint<2>& a, const ClosestPoint<2>& b) {
    if (a.where.patch != b.where.patch) return false;
    const double n = double(domain_.loops[std::size_t(a.where.patch)].n_pieces());
    double dt = std::abs(a.where.param[0] - b.where.param[0]);
    dt = std::min(dt, n - dt);
    return dt <= 1e-9 || (a.point - b.point).norm() <= 1e-12 * scale_;
  };
  for (const ClosestPoint<2>& c : all) {
    if (int(result.size()) >= max_count) break;
    bool dup = false;
    for (const ClosestPoint<2>& r : result) dup = dup || same(c, r);
    if (!dup) result.push_back(c);
  }
  return result;
}

ClosestPoint<2> CurveBoundary::closest_point_ref(const P2& p, int samples) const {
  // Every piece: its best sample, polished by golden section within one sample step.
  double best = inf, best_u = 0.0;
  int best_rec = 0;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int r = 0; r < int(pieces_.size()); ++r) {
    const Bezier& q = pieces_[std::size_t(r)].q;
    auto f = [&](double u) { return (bezier_point(q, u) - p).squaredNorm(); };
    double piece_best = inf, su = 0.0;
    for (int k = 0; k <= samples; ++k)
      if (f(double(k) / samples) < piece_best) { piece_best = f(double(k) / samples); su = double(k) / samples; }
    double lo = std::max(0.0, su - 1.0 / samples), hi = std::min(1.0, su + 1.0 / samples);
    for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
      const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
      if (f(a) < f(b)) hi = b;
      else lo = a;
    }
    for (double u : {0.5 * (lo + hi), su})
      if (f(u) < best) { best = f(u); best_u = u; best_rec = r; }
  }
  return make_result(best_rec, best_u, p);
}

// ---------------------------------------------------------------------------------------------
// Inside, classify, segments

// A horizontal ray meets few pieces, but the BVH walk to them was most of classify's cost
// (flange level 9: 600 instructions a point in the walk, 200 in ray_crossings).
void CurveBoundary::build_ray_bands() {
  constexpr std::size_t max_entries = std::size_t(1) << 22;
  std::vector<double> ys;
  ys.reserve(2 * pieces_.size());
  for (const Piece& pc : pieces_) {
    if (!std::isfinite(pc.box.lo.y()) || !std::isfinite(pc.box.hi.y())) return;
    ys.push_back(pc.box.lo.y());
    ys.push_back(pc.box.hi.y());
  }
  std::sort(ys.begin(), ys.end());
  ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
  auto index_of = [&](double y) { return std::size_t(std::lower_bound(ys.begin(), ys.end(), y) - ys.begin()); };
  // Piece r (bounds at indices a <= b) is in bands a + 1 .. b.
  std::vector<std::int32_t> first(ys.size() + 2, 0);
  std::size_t total = 0;
  for (const Piece& pc : pieces_) {
    const std::size_t a = index_of(pc.box.lo.y()), b = index_of(pc.box.hi.y());
    for (std::size_t j = a + 1; j <= b; ++j) ++first[j + 1];
    total += b - a;
    if (total > max_entries) return;
  }
  for (std::size_t j = 0; j + 1 < first.size(); ++j) first[j + 1] += first[j];
  std::vector<std::int32_t> piece(total);
  std::vector<std::int32_t> fill(first.begin(), first.end() - 1);
  for (std::size_t r = 0; r < pieces_.size(); ++r) {
    const std::size_t a = index_of(pieces_[r].box.lo.y()), b = index_of(pieces_[r].box.hi.y());
    for (std::size_t j = a + 1; j <= b; ++j) piece[std::size_t(fill[j]++)] = std::int32_t(r);
  }
  band_y_ = std::move(ys);
  band_first_ = std::move(first);
  band_piece_ = std::move(piece);
}

bool CurveBoundary::is_inside(const P2& p) const {
  int w = 0;
  if (!band_first_.empty()) {
    // The same sum as the BVH walk's: the pieces it leaves out add 0 (ray_crossings returns 0
    // unless lo.y < y <= hi.y and hi.x > x, on the same control box).
    const std::size_t j = std::size_t(std::lower_bound(band_y_.begin(), band_y_.end(), p.y()) - band_y_.begin());
    for (std::int32_t k = band_first_[j]; k < band_first_[j + 1]; ++k) {
      const Piece& pc = pieces_[std::size_t(band_piece_[std::size_t(k)])];
      if (pc.box.hi.x() > p.x()) w += ray_crossings(pc.q, p);
    }
    return w != 0;
  }
  traverse([&](const Box<2>& b) { return b.lo.y() <= p.y() && b.hi.y() >= p.y() && b.hi.x() > p.x(); },
           [&](int r) { w += ray_crossings(pieces_[std::size_t(r)].q, p); });
  return w != 0;
}

bool CurveBoundary::piece_meets_box(int rec, const Box<2>& box) const {
  return curve_meets_box(pieces_[std::size_t(rec)].q, box, 1e-13 * scale_, 60);
}

Side CurveBoundary::classify(const Box<2>& box) const {
  bool partial = false;
  traverse([&](const Box<2>& b) { return !partial && b.overlaps(box); },
           [&](int r) { partial = partial || piece_meets_box(r, box); });
  if (partial) return Side::Partial;
  return is_inside(box.center()) ? Side::In : Side::Out;
}

Side CurveBoundary::classify_ref(const Box<2>& box) const {
  for (int r = 0; r < int(pieces_.size()); ++r)
    if (piece_meets_box(r, box)) return Side::Partial;
  int w = 0;
  for (const Loop& l : domain_.loops) w += winding_number(l, box.center());
  return w != 0 ? Side::In : Side::Out;
}

bool CurveBoundary::segment_hits(const P2& a, const P2& b, double s_lo, double s_hi) const {
  const P2 d = b - a;
  const double len2 = d.squaredNorm();
  Box<2> sb{a.cwiseMin(b), a.cwiseMax(b)};
  if (len2 == 0.0) {
    bool hit = false;
    traverse([&](const Box<2>& bx) { return !hit && bx.contains(a); },
             [&](int r) { hit = hit || piece_meets_box(r, sb); });
    return hit;
  }
  bool hit = false;
  traverse([&](const Box<2>& bx) { return !hit && bx.overlaps(sb); },
           [&](int r) {
             hit = hit || curve_hits_segment(pieces_[std::size_t(r)].q, a, d, len2, s_lo, s_hi, 1e-13 * scale_, 60);
           });
  return hit;
}

bool CurveBoundary::segment_touches(const P2& a, const P2& b) const { return segment_hits(a, b, 0.0, 1.0); }

bool CurveBoundary::segment_crosses(const P2& a, const P2& b) const {
  const double len = (b - a).norm();
  const double margin = 1e-10 * scale_;
  if (len <= 2.0 * margin) return false;
  return segment_hits(a, b, margin / len, 1.0 - margin / len);
}

// ---------------------------------------------------------------------------------------------
// Control levels

void CurveBoundary::set_root_scale(double scale) {
  root_scale_ = scale;
  file_level_shift_ = scale == 1.0 ? 0.0 : std::log2(scale);
  compute_automatic_levels();
}

Box<2> CurveBoundary::root_box() const {
  const double side = default_root_side(bbox_) * root_scale_;
  const P2 c = bbox_.center();
  return Box<2>{c - P2::Constant(0.5 * side), c + P2::Constant(0.5 * side)};
}

bool CurveBoundary::is_automatic() const {
  return !has_curve_levels_ && domain_.interior.empty() && global_level_ == no_level && domain_.default_level == no_level;
}

double CurveBoundary::level_at(int loop, double t) const {
  const std::vector<int>& js = level_junctions_[std::size_t(loop)];
  const Loop& l = domain_.loops[std::size_t(loop)];
  if (js.empty()) return no_level;
  if (js.size() == 1) return l.level[std::size_t(js[0])];
  const double n = double(l.n_pieces());
  const double w = wrap_parameter(l, t);
  // Previous and next junctions with a level, periodically.
  auto it = std::upper_bound(js.begin(), js.end(), w, [](double v, int j) { return v < double(j); });
  const int j1 = it == js.end() ? js.front() : *it;
  const int j0 = it == js.begin() ? js.back() : *(it - 1);
  double span = double(j1) - double(j0);
  if (span <= 0.0) span += n;
  double along = w - double(j0);
  if (along < 0.0) along += n;
  const double a = along / span;
  return (1.0 - a) * l.level[std::size_t(j0)] + a * l.level[std::size_t(j1)];
}

double CurveBoundary::automatic_level(int loop, std::size_t piece) const {
  return auto_level_.empty() ? 0.0 : auto_level_[std::size_t(loop)][piece];
}

double CurveBoundary::local_thickness(const P2& s) const {
  // The nearest local minimum of the distance from s other than s itself.
  const double floor2 = (1e-9 * scale_) * (1e-9 * scale_);
  double best = inf;
  std::vector<Candidate> cands;
  traverse([&](const Box<2>& b) { return box_distance2(b, s) < best; },
           [&](int r) {
             if (box_distance2(pieces_[std::size_t(r)].box, s) >= best) return;
             cands.clear();
             piece_local_minima(r, s, best, cands);
             junction_minima(r, s, cands);
             for (const Candidate& c : cands)
               if (c.d2 > floor2) best = std::min(best, c.d2);
           });
  return std::sqrt(best);
}

double CurveBoundary::feature_thickness(const P2& s, int loop, int piece) const {
  const double floor2 = (1e-9 * scale_) * (1e-9 * scale_);
  const int n = int(domain_.loops[std::size_t(loop)].n_pieces());
  auto adjacent = [&](const Piece& pc) {
    if (pc.loop != loop) return false;
    const int d = std::abs(pc.index - piece);
    return d <= 1 || d >= n - 1;
  };
  double best = inf;
  std::vector<Candidate> cands;
  traverse([&](const Box<2>& b) { return box_distance2(b, s) < best; },
           [&](int r) {
             const Piece& pc = pieces_[std::size_t(r)];
             if (adjacent(pc) || box_distance2(pc.box, s) >= best) return;
             cands.clear();
             piece_local_minima(r, s, best, cands);
             junction_minima(r, s, cands);
             for (const Candidate& c : cands)
               if (c.d2 > floor2) best = std::min(best, c.d2);
           });
  return std::sqrt(best);
}

void CurveBoundary::compute_automatic_levels() {
  const double root = root_box().extent().x();
  auto level_for = [&](double h) { return h > 0.0 ? std::max(0.0, std::ceil(std::log2(root / h))) : 0.0; };
  const bool automatic = !(has_curve_levels_ || !domain_.interior.empty() || domain_.default_level != no_level);
  if (automatic) auto_level_.resize(domain_.loops.size());
  floor_level_.resize(domain_.loops.size());
  for (std::size_t i = 0; i < domain_.loops.size(); ++i) {
    const Loop& l = domain_.loops[i];
    if (automatic) auto_level_[i].assign(l.n_pieces(), 0.0);
    floor_level_[i].assign(l.n_pieces(), 0.0);
    for (std::size_t k = 0; k < l.n_pieces(); ++k) {
      const Bezier& q = l.pieces[k];
      double thick_lv = 0.0, feature_lv = 0.0;
      for (int j = 0; j < 8; ++j) {
        const P2 s = bezier_point(q, (j + 0.5) / 8.0);
        const double feature = feature_thickness(s, int(i), int(k));
        if (std::isfinite(feature)) feature_lv = std::max(feature_lv, level_for(feature / quadrants_across_feature));
        if (!automatic) continue;
        const double thick = local_thickness(s);
        if (std::isfinite(thick)) thick_lv = std::max(thick_lv, level_for(thick / quadrants_across_feature));
      }
      double kmax = 0.0;
      for (int j = 0; j <= 32; ++j) kmax = std::max(kmax, std::abs(bezier_curvature(q, j / 32.0)));
      const double curvature_lv = kmax > 0.0 ? level_for(cells_per_radius / kmax) : 0.0;
      floor_level_[i][k] = std::max(feature_lv, curvature_lv);
      if (automatic) auto_level_[i][k] = std::max(thick_lv, curvature_lv);
    }
  }
}

double CurveBoundary::control_level(const Box<2>& box) const { return control_level(box, floor_boost_default); }

double CurveBoundary::control_level(const Box<2>& box, double floor_boost) const {
  double lv = 0.0;
  const double global = global_level_ != no_level ? global_level_
                        : domain_.default_level != no_level ? domain_.default_level + file_level_shift_
                                                            : no_level;
  if (global != no_level) lv = std::max(lv, global);
  for (const InteriorControl& c : domain_.interior)
    if (box_distance2(box, c.p) <= c.radius * c.radius) lv = std::max(lv, c.level + file_level_shift_);
  const bool automatic = is_automatic();
  // Features thinner than the quadrants and bends tighter than them are refined until resolved,
  // even with given levels (at most floor_boost levels above what was asked).
  const double given = lv;
  traverse([&](const Box<2>& b) { return b.overlaps(box); },
           [&](int r) {
             const Piece& pc = pieces_[std::size_t(r)];
             if (!automatic) {
               const double floor = std::min(floor_level_[std::size_t(pc.loop)][std::size_t(pc.index)],
                                             std::min(double(max_level_), given + floor_boost));
               if (floor > lv && piece_meets_box(r, box)) lv = floor;
             }
             if (automatic) {
               if (auto_level_[std::size_t(pc.loop)][std::size_t(pc.index)] > lv && piece_meets_box(r, box))
                 lv = std::min(double(max_level_), auto_level_[std::size_t(pc.loop)][std::size_t(pc.index)]);
               return;
             }
             if (level_junctions_[std::size_t(pc.loop)].empty()) return;
             double lo = inf, hi = -inf;
             meeting_range(pc.q, box, 0.0, 1.0, 1e-13 * scale_, 60, lo, hi);
             if (lo > hi) return;
             for (const double at : {level_at(pc.loop, pc.index + lo), level_at(pc.loop, pc.index + hi)})
               if (at != no_level) lv = std::max(lv, at + file_level_shift_);
           });
  return lv;
}

// ---------------------------------------------------------------------------------------------
// Small queries

int CurveBoundary::n_components() const { return int(std::count(hole_.begin(), hole_.end(), 0)); }
int CurveBoundary::n_holes() const { return int(hole_.size()) - n_components(); }
double CurveBoundary::area() const { return std::accumulate(signed_area_.begin(), signed_area_.end(), 0.0); }
double CurveBoundary::signed_area(int loop) const { return signed_area_[std::size_t(loop)]; }
double CurveBoundary::length(int loop) const { return length_[std::size_t(loop)]; }
P2 CurveBoundary::evaluate(int loop, double t) const { return dim2::evaluate(domain_.loops[std::size_t(loop)], t); }
P2 CurveBoundary::derivative(int loop, double t) const { return dim2::derivative(domain_.loops[std::size_t(loop)], t); }
P2 CurveBoundary::tangent(int loop, double t) const { return dim2::tangent(domain_.loops[std::size_t(loop)], t); }
double CurveBoundary::curvature(int loop, double t) const { return dim2::curvature(domain_.loops[std::size_t(loop)], t); }
int CurveBoundary::corner_index(int loop, std::size_t piece) const { return corner_of_[std::size_t(loop)][piece]; }
double CurveBoundary::advance(int loop, double t, double s) const { return dim2::advance(domain_.loops[std::size_t(loop)], t, s); }
double CurveBoundary::arc_length(int loop, double t0, double t1) const {
  return dim2::arc_length(domain_.loops[std::size_t(loop)], t0, t1);
}

}  // namespace febemesh::dim2
