#pragma once
// A cell size instead of a level (mesh2d's and mesh3d's --size): the level whose cells in the
// default root cube are no larger, and the root cube enlarged by less than 2x so that they are
// exactly that size. Both dimensions' root cubes are default_root_side times the scale
// (dim2::CurveBoundary::root_box, dim3::SurfaceBoundary::root_box).

#include <algorithm>
#include <cmath>

#include "core/box.hpp"

namespace febemesh {

/// The side of the default root cube (square) around `bounding_box`: 1.05 x its largest extent.
/// dim2::CurveBoundary::root_box and dim3::SurfaceBoundary::root_box are this times their scale.
template <int Dim> double default_root_side(const Box<Dim>& bounding_box) {
  return 1.05 * bounding_box.extent().maxCoeff();
}

struct SizedLevel {
  int level = 1;
  double root_scale = 1.0;  ///< the root cube's side over its default
};

/// The level (at least 1) whose cells in the default root cube around `bounding_box` are no
/// larger than `size`, and the root scale (in [1, 2) unless `size` needs a level under 1) that
/// makes that level's cells `size`. A size that is a level's cell in the default cube, to
/// rounding, is that level at scale 1 (the same tree as asking for the level).
template <int Dim> SizedLevel level_for_size(const Box<Dim>& bounding_box, double size) {
  const double side = default_root_side(bounding_box);
  SizedLevel sl;
  sl.level = std::max(1, static_cast<int>(std::ceil(std::log2(side / size))));
  sl.root_scale = size * std::ldexp(1.0, sl.level) / side;
  // log2's rounding at a power of two: the level below it at scale 2, or the level above at
  // a scale just under 1.
  if (sl.level > 1 && std::abs(sl.root_scale - 2.0) < 2e-12) sl.level -= 1, sl.root_scale = 1.0;
  if (std::abs(sl.root_scale - 1.0) < 1e-12) {
    sl.root_scale = 1.0;
  } else if (sl.root_scale < 1.0) {
    sl.level += 1;
    sl.root_scale *= 2.0;
  }
  return sl;
}

}  // namespace febemesh
