#pragma once
// Analytic solids implementing Boundary<Dim> for tests: a ball (Circle in 2D, Sphere in 3D) and
// an axis-aligned box. Classification is exact up to rounding and strict: IN boxes lie strictly
// inside, OUT boxes strictly outside, everything that touches the boundary is PARTIAL.

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/boundary.hpp"

namespace febemesh::test {

template <int Dim> class Ball final : public Boundary<Dim> {
 public:
  Ball(const Point<Dim>& center, double radius, double level = 0.0)
      : center_(center), radius_(radius), level_(level) {}

  const Point<Dim>& center() const { return center_; }
  double radius() const { return radius_; }

  Box<Dim> bounding_box() const override {
    return {center_ - Point<Dim>::Constant(radius_), center_ + Point<Dim>::Constant(radius_)};
  }
  Side classify(const Box<Dim>& b) const override {
    const double near = nearest_distance(b), far = farthest_distance(b);
    if (far < radius_) return Side::In;
    if (near > radius_) return Side::Out;
    return Side::Partial;
  }
  bool is_inside(const Point<Dim>& p) const override { return (p - center_).norm() < radius_; }
  ClosestPoint<Dim> closest_point(const Point<Dim>& p) const override {
    Point<Dim> dir = p - center_;
    const double r = dir.norm();
    if (r == 0.0) {
      dir.setZero();
      dir[0] = 1.0;
    } else {
      dir /= r;
    }
    ClosestPoint<Dim> cp;
    cp.point = center_ + radius_ * dir;
    cp.distance = std::abs(r - radius_);
    cp.where.patch = 0;
    cp.where.param[0] = std::atan2(dir[1], dir[0]);
    return cp;
  }
  std::vector<ClosestPoint<Dim>> closest_points(const Point<Dim>& p, int max_count) const override {
    std::vector<ClosestPoint<Dim>> out;
    if (max_count <= 0) return out;
    out.push_back(closest_point(p));
    // The antipodal point is the other critical point of the distance.
    if (max_count > 1) {
      ClosestPoint<Dim> far = out.front();
      far.point = 2.0 * center_ - far.point;
      far.distance = (far.point - p).norm();
      out.push_back(far);
    }
    return out;
  }
  bool segment_crosses(const Point<Dim>& a, const Point<Dim>& b) const override {
    // |a + s (b - a) - c|^2 = r^2 for some s in (0, 1).
    const Point<Dim> d = b - a, f = a - center_;
    const double A = d.squaredNorm(), B = 2.0 * f.dot(d), C = f.squaredNorm() - radius_ * radius_;
    if (A == 0.0) return false;
    const double disc = B * B - 4.0 * A * C;
    if (disc < 0.0) return false;
    const double s1 = (-B - std::sqrt(disc)) / (2.0 * A), s2 = (-B + std::sqrt(disc)) / (2.0 * A);
    return (s1 > 0.0 && s1 < 1.0) || (s2 > 0.0 && s2 < 1.0);
  }
  double control_level(const Box<Dim>& b) const override {
    return classify(b) == Side::Partial ? level_ : 0.0;
  }

  double nearest_distance(const Box<Dim>& b) const {
    const Point<Dim> q = center_.cwiseMax(b.lo).cwiseMin(b.hi);
    return (q - center_).norm();
  }
  double farthest_distance(const Box<Dim>& b) const {
    Point<Dim> q;
    for (int d = 0; d < Dim; ++d) {
      q[d] = std::abs(b.lo[d] - center_[d]) > std::abs(b.hi[d] - center_[d]) ? b.lo[d] : b.hi[d];
    }
    return (q - center_).norm();
  }

 private:
  Point<Dim> center_;
  double radius_;
  double level_;
};

using Circle = Ball<2>;
using Sphere = Ball<3>;

/// An axis-aligned box solid (named BoxSolid to keep febemesh::Box the plain box type).
template <int Dim> class BoxSolid final : public Boundary<Dim> {
 public:
  explicit BoxSolid(const Box<Dim>& box, double level = 0.0) : box_(box), level_(level) {}

  Box<Dim> bounding_box() const override { return box_; }
  Side classify(const Box<Dim>& b) const override {
    if ((b.lo.array() > box_.lo.array()).all() && (b.hi.array() < box_.hi.array()).all()) return Side::In;
    if ((b.hi.array() < box_.lo.array()).any() || (b.lo.array() > box_.hi.array()).any()) return Side::Out;
    return Side::Partial;
  }
  bool is_inside(const Point<Dim>& p) const override {
    return (p.array() > box_.lo.array()).all() && (p.array() < box_.hi.array()).all();
  }
  ClosestPoint<Dim> closest_point(const Point<Dim>& p) const override {
    ClosestPoint<Dim> cp;
    cp.where.patch = 0;
    if (!is_inside(p)) {
      cp.point = p.cwiseMax(box_.lo).cwiseMin(box_.hi);
    } else {
      // Inside: project onto the nearest face.
      double best = std::numeric_limits<double>::infinity();
      for (int d = 0; d < Dim; ++d) {
        for (const double plane : {box_.lo[d], box_.hi[d]}) {
          if (std::abs(p[d] - plane) < best) {
            best = std::abs(p[d] - plane);
            cp.point = p;
            cp.point[d] = plane;
          }
        }
      }
    }
    cp.distance = (cp.point - p).norm();
    return cp;
  }
  std::vector<ClosestPoint<Dim>> closest_points(const Point<Dim>& p, int max_count) const override {
    if (max_count <= 0) return {};
    return {closest_point(p)};
  }
  bool segment_crosses(const Point<Dim>& a, const Point<Dim>& b) const override {
    // The open segment meets the boundary iff it is not entirely inside and not entirely
    // outside the closed box; clip it against the slabs (Liang-Barsky).
    const bool a_in = is_inside(a), b_in = is_inside(b);
    if (a_in != b_in) return true;
    if (a_in && b_in) return false;  // convex: the whole segment is strictly inside
    double s0 = 0.0, s1 = 1.0;
    for (int d = 0; d < Dim; ++d) {
      const double delta = b[d] - a[d];
      if (delta == 0.0) {
        if (a[d] < box_.lo[d] || a[d] > box_.hi[d]) return false;
        continue;
      }
      double u0 = (box_.lo[d] - a[d]) / delta, u1 = (box_.hi[d] - a[d]) / delta;
      if (u0 > u1) std::swap(u0, u1);
      s0 = std::max(s0, u0);
      s1 = std::min(s1, u1);
    }
    return s0 <= s1 && s1 > 0.0 && s0 < 1.0;
  }
  double control_level(const Box<Dim>& b) const override {
    return classify(b) == Side::Partial ? level_ : 0.0;
  }

 private:
  Box<Dim> box_;
  double level_;
};

}  // namespace febemesh::test
