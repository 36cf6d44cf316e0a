#pragma once
// The seam between the generic core and a dimension (DESIGN.md): what the tree and the
// boundary-cell construction ask of the boundary. dim2 (B-spline loops) and dim3 (triangulated
// surface) implement it; tests implement it with analytic shapes (circle, sphere, box).

#include <cstdint>
#include <vector>

#include "core/box.hpp"

namespace febemesh {

enum class Side : std::uint8_t { Out = 0, In = 1, Partial = 2 };

/// Where on the boundary a point lies. 2D: patch = loop index, param[0] = curve parameter.
/// 3D: patch = triangle index, param = barycentric (u, v). `kind` says whether the point is on
/// the smooth part, on a feature edge (3D) or on a corner/feature vertex.
struct BoundaryLocation {
  enum class Kind : std::uint8_t { Smooth = 0, FeatureEdge = 1, Corner = 2 };
  std::int32_t patch = -1;
  double param[2] = {0.0, 0.0};
  Kind kind = Kind::Smooth;
  std::int32_t feature = -1;  ///< corner index or feature-edge index when kind != Smooth
};

template <int Dim> struct ClosestPoint {
  Point<Dim> point = Point<Dim>::Zero();
  double distance = 0.0;
  BoundaryLocation where;
};

template <int Dim> class Boundary {
 public:
  virtual ~Boundary() = default;

  /// Tight box around the whole boundary.
  virtual Box<Dim> bounding_box() const = 0;
  /// IN: box entirely inside the solid; OUT: entirely outside; PARTIAL: the boundary meets it.
  /// May answer PARTIAL conservatively, never IN or OUT wrongly.
  virtual Side classify(const Box<Dim>& box) const = 0;
  /// Point strictly inside the solid (winding number / ray parity).
  virtual bool is_inside(const Point<Dim>& p) const = 0;
  /// Closest boundary point (paper eq. 1).
  virtual ClosestPoint<Dim> closest_point(const Point<Dim>& p) const = 0;
  /// Local minima of the distance, nearest first (the paper takes the next normal when the
  /// nearest one crosses a cell). The first entry equals closest_point(p).
  virtual std::vector<ClosestPoint<Dim>> closest_points(const Point<Dim>& p, int max_count) const = 0;
  /// Does the open segment (a, b) cross or touch the boundary?
  virtual bool segment_crosses(const Point<Dim>& a, const Point<Dim>& b) const = 0;
  /// Largest mesh control parameter (a target tree level) wanted inside `box`; 0 if none.
  virtual double control_level(const Box<Dim>& box) const = 0;
};

}  // namespace febemesh
