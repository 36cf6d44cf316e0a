#pragma once
// Real-valued points and axis-aligned boxes: where lattice cells meet geometry.

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // determinants
#include <Eigen/Geometry>  // cross(): declared by Core, defined here
#include <limits>

namespace febemesh {

template <int Dim> using Point = Eigen::Matrix<double, Dim, 1>;

template <int Dim> struct Box {
  Point<Dim> lo = Point<Dim>::Zero();
  Point<Dim> hi = Point<Dim>::Zero();

  Point<Dim> center() const { return 0.5 * (lo + hi); }
  Point<Dim> extent() const { return hi - lo; }
  bool contains(const Point<Dim>& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
  bool overlaps(const Box& b) const {
    return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all();
  }
  void expand(const Point<Dim>& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  /// An empty box that any expand() replaces.
  static Box empty() {
    Box b;
    b.lo.setConstant(std::numeric_limits<double>::infinity());
    b.hi.setConstant(-std::numeric_limits<double>::infinity());
    return b;
  }
};

}  // namespace febemesh
