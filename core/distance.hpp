#pragma once
// Point-to-segment distance, for fidelity measures (Hausdorff estimates) in 2D and 3D.

#include <algorithm>

#include "core/box.hpp"

namespace febemesh {

template <int Dim>
double point_segment_distance(const Point<Dim>& p, const Point<Dim>& a, const Point<Dim>& b) {
  const Point<Dim> ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

}  // namespace febemesh
