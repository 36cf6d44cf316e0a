#pragma once
// Facet tables that truly differ by dimension (STYLE.md §2). Corner numbering: bit d of a corner
// index = upper along axis d. Facet f: axis f/2, lower (even) or upper (odd) side.

#include <array>

#include "core/box.hpp"
#include "core/cube.hpp"

namespace febemesh {

template <int Dim> struct FaceCorners;  // primary undefined: no silent fallback

/// 2D: each edge's two corners in counter-clockwise order around the cell (outward normal on
/// the right), so a cell's edges chain into its CCW boundary.
template <> struct FaceCorners<2> {
  static constexpr std::array<std::array<int, 2>, 4> corners = {{{2, 0}, {1, 3}, {0, 1}, {3, 2}}};
  /// The cell's corners in CCW order.
  static constexpr std::array<int, 4> ring = {0, 1, 3, 2};
};

/// 3D: each face's four corners ordered counter-clockwise seen from outside the cell.
template <> struct FaceCorners<3> {
  static constexpr std::array<std::array<int, 4>, 6> corners = {{
      {0, 4, 6, 2},  // x-low
      {1, 3, 7, 5},  // x-high
      {0, 1, 5, 4},  // y-low
      {2, 6, 7, 3},  // y-high
      {0, 2, 3, 1},  // z-low
      {4, 5, 7, 6},  // z-high
  }};
};

/// Outward unit normal of facet f of a cell: axis f / 2, towards lower coordinates for even f.
template <int Dim> Point<Dim> facet_normal(int f) {
  Point<Dim> n = Point<Dim>::Zero();
  n[f / 2] = (f % 2) ? 1.0 : -1.0;
  return n;
}

}  // namespace febemesh
