#include "dim3/triangle_predicates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace febemesh::dim3 {

namespace {

using P2 = Point<2>;

int sign_with_tol(double value, double scale) {
  if (std::abs(value) <= kOrientEps * scale) return 0;
  return value > 0.0 ? 1 : -1;
}

int orient2d(const P2& a, const P2& b, const P2& c) {
  const P2 ab = b - a, ac = c - a;
  return sign_with_tol(ab.x() * ac.y() - ab.y() * ac.x(), ab.norm() * ac.norm());
}

/// Drop the axis along which the plane of (a, b, c) is steepest, keeping the others.
int dominant_axis(const P3& a, const P3& b, const P3& c) {
  const P3 n = (b - a).cross(c - a).cwiseAbs();
  int axis = 0;
  if (n[1] > n[axis]) axis = 1;
  if (n[2] > n[axis]) axis = 2;
  return axis;
}

P2 drop(const P3& p, int axis) {
  return axis == 0 ? P2(p.y(), p.z()) : axis == 1 ? P2(p.z(), p.x()) : P2(p.x(), p.y());
}

/// Closed point-in-triangle in 2D (either orientation of the triangle).
bool in_triangle_2d(const P2& p, const P2& a, const P2& b, const P2& c, bool strict) {
  const int s1 = orient2d(a, b, p), s2 = orient2d(b, c, p), s3 = orient2d(c, a, p);
  if (strict) return s1 != 0 && s1 == s2 && s2 == s3;
  const bool has_pos = s1 > 0 || s2 > 0 || s3 > 0, has_neg = s1 < 0 || s2 < 0 || s3 < 0;
  return !(has_pos && has_neg);
}

/// Segments [a, b] and [c, d] in 2D: strict = proper crossing only; else any contact.
bool segments_meet_2d(const P2& a, const P2& b, const P2& c, const P2& d, bool strict) {
  const int s1 = orient2d(a, b, c), s2 = orient2d(a, b, d);
  const int s3 = orient2d(c, d, a), s4 = orient2d(c, d, b);
  if (strict) return s1 * s2 < 0 && s3 * s4 < 0;
  if (s1 * s2 > 0 || s3 * s4 > 0) return false;
  if (s1 != 0 || s2 != 0) return true;  // not collinear: the sign tests decide
  // Collinear: compare the projections on the line's direction.
  const P2 dir = b - a;
  double t0 = 0.0, t1 = dir.squaredNorm(), u0 = (c - a).dot(dir), u1 = (d - a).dot(dir);
  if (u0 > u1) std::swap(u0, u1);
  return u0 <= t1 && u1 >= t0;
}

}  // namespace

int orient3d(const P3& a, const P3& b, const P3& c, const P3& d) {
  const P3 ab = b - a, ac = c - a, ad = d - a;
  return sign_with_tol(ab.cross(ac).dot(ad), ab.norm() * ac.norm() * ad.norm());
}

TrianglePoint closest_on_triangle(const P3& p, const P3& a, const P3& b, const P3& c) {
  const P3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, 0.0, 0.0, TriangleRegion::Vertex0};
  const P3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, 1.0, 0.0, TriangleRegion::Vertex1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double t = d1 - d3 > 0.0 ? d1 / (d1 - d3) : 0.0;
    return {a + t * ab, t, 0.0, TriangleRegion::Edge0};
  }
  const P3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, 0.0, 1.0, TriangleRegion::Vertex2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double t = d2 - d6 > 0.0 ? d2 / (d2 - d6) : 0.0;
    return {a + t * ac, 0.0, t, TriangleRegion::Edge2};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    const double den = (d4 - d3) + (d5 - d6);
    const double t = den > 0.0 ? (d4 - d3) / den : 0.0;
    return {b + t * (c - b), 1.0 - t, t, TriangleRegion::Edge1};
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) return {a, 0.0, 0.0, TriangleRegion::Vertex0};  // zero-area triangle
  const double v = vb / sum, w = vc / sum;
  return {a + v * ab + w * ac, v, w, TriangleRegion::Face};
}

double closest_on_segment(const P3& p, const P3& a, const P3& b) {
  const P3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0.0)) return 0.0;
  return std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
}

double line_triangle_parameter(const P3& p, const P3& q, const P3& a, const P3& b, const P3& c) {
  constexpr double none = std::numeric_limits<double>::infinity();
  const P3 e1 = b - a, e2 = c - a, d = q - p;
  const P3 pv = d.cross(e2);
  const double det = e1.dot(pv);
  if (std::abs(det) < 1e-300) return none;
  const P3 tv = p - a;
  const double u = tv.dot(pv) / det;
  if (u < 0 || u > 1) return none;
  const P3 qv = tv.cross(e1);
  const double w = d.dot(qv) / det;
  if (w < 0 || u + w > 1) return none;
  return e2.dot(qv) / det;
}

Crossing segment_triangle(const P3& p, const P3& q, const P3& a, const P3& b, const P3& c) {
  const int sp = orient3d(a, b, c, p), sq = orient3d(a, b, c, q);
  if (sp * sq > 0) return Crossing::Miss;
  if (sp == 0 && sq == 0) {
    const int axis = dominant_axis(a, b, c);
    const P2 p2 = drop(p, axis), q2 = drop(q, axis), a2 = drop(a, axis), b2 = drop(b, axis),
             c2 = drop(c, axis);
    const bool meets = in_triangle_2d(p2, a2, b2, c2, false) || in_triangle_2d(q2, a2, b2, c2, false) ||
                       segments_meet_2d(p2, q2, a2, b2, false) ||
                       segments_meet_2d(p2, q2, b2, c2, false) ||
                       segments_meet_2d(p2, q2, c2, a2, false);
    return meets ? Crossing::Degenerate : Crossing::Miss;
  }
  const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
  const bool has_pos = s1 > 0 || s2 > 0 || s3 > 0, has_neg = s1 < 0 || s2 < 0 || s3 < 0;
  if (has_pos && has_neg) return Crossing::Miss;
  if (!has_pos && !has_neg) return Crossing::Degenerate;
  if (s1 == 0 || s2 == 0 || s3 == 0 || sp == 0 || sq == 0) return Crossing::Degenerate;
  return Crossing::Proper;
}

bool triangles_intersect(const P3 (&t1)[3], const P3 (&t2)[3]) {
  int side1[3], side2[3];
  for (int i = 0; i < 3; ++i) {
    side1[i] = orient3d(t2[0], t2[1], t2[2], t1[i]);
    side2[i] = orient3d(t1[0], t1[1], t1[2], t2[i]);
  }
  auto all_same_strict = [](const int (&s)[3]) { return s[0] != 0 && s[0] == s[1] && s[1] == s[2]; };
  if (all_same_strict(side1) || all_same_strict(side2)) return false;
  const bool coplanar = side1[0] == 0 && side1[1] == 0 && side1[2] == 0 && side2[0] == 0 &&
                        side2[1] == 0 && side2[2] == 0;
  if (!coplanar) {
    for (int i = 0; i < 3; ++i) {
      if (segment_triangle(t1[i], t1[(i + 1) % 3], t2[0], t2[1], t2[2]) != Crossing::Miss) return true;
      if (segment_triangle(t2[i], t2[(i + 1) % 3], t1[0], t1[1], t1[2]) != Crossing::Miss) return true;
    }
    return false;
  }
  const int axis = dominant_axis(t1[0], t1[1], t1[2]);
  P2 a[3], b[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = drop(t1[i], axis);
    b[i] = drop(t2[i], axis);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_meet_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], false)) return true;
  // No edges meet: they meet only if one lies inside the other.
  return in_triangle_2d(a[0], b[0], b[1], b[2], false) || in_triangle_2d(b[0], a[0], a[1], a[2], false);
}

bool box_triangle_overlap(const Box<3>& box, const P3& a, const P3& b, const P3& c) {
  const P3 centre = box.center(), h = 0.5 * box.extent();
  const P3 v[3] = {a - centre, b - centre, c - centre};
  // Box face normals: the triangle's box against the box.
  for (int d = 0; d < 3; ++d) {
    const double lo = std::min({v[0][d], v[1][d], v[2][d]}), hi = std::max({v[0][d], v[1][d], v[2][d]});
    if (lo > h[d] || hi < -h[d]) return false;
  }
  // Triangle normal: the plane against the box.
  const P3 f[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  const P3 n = f[0].cross(f[1]);
  if (std::abs(n.dot(v[0])) > h.dot(n.cwiseAbs())) return false;
  // Cross products of box axes and triangle edges.
  for (int d = 0; d < 3; ++d)
    for (int j = 0; j < 3; ++j) {
      const P3 axis = P3::Unit(d).cross(f[j]);
      const double p0 = axis.dot(v[0]), p1 = axis.dot(v[1]), p2 = axis.dot(v[2]);
      const double r = h.dot(axis.cwiseAbs());
      if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
    }
  return true;
}

}  // namespace febemesh::dim3
