// core/sized_level.hpp: a cell size gives the level whose cells are no larger and the root scale
// that makes them exactly that size (mesh2d's and mesh3d's --size).

#include <catch2/catch.hpp>

#include <cmath>

#include "core/sized_level.hpp"

using namespace febemesh;

TEST_CASE("level_for_size: the level and root scale whose octants have the size asked", "[size]") {
  Box<3> b;
  b.lo = Point<3>(-1.0, 0.0, 0.0);
  b.hi = Point<3>(1.0, 0.5, 0.25);  // the largest extent 2: the default cube 2.1 across
  const double side = 2.1;
  for (const double size : {0.3, 0.13125, 0.1, 0.02, 0.0042}) {
    const SizedLevel sl = level_for_size<3>(b, size);
    INFO("size " << size << ": level " << sl.level << ", scale " << sl.root_scale);
    CHECK(sl.level >= 1);
    CHECK(sl.root_scale >= 1.0);
    CHECK(sl.root_scale < 2.0);
    CHECK(side * sl.root_scale / std::ldexp(1.0, sl.level) == Approx(size).epsilon(1e-12));
  }
  // The default cube's level-4 octant (2.1 / 16 = 0.13125): level 4 in the default cube.
  const SizedLevel l4 = level_for_size<3>(b, 0.13125);
  CHECK(l4.level == 4);
  CHECK(l4.root_scale == 1.0);
  CHECK(level_for_size<3>(b, 0.3).level == 3);  // 2.1 / 8 = 0.2625 < 0.3: level 3 in a cube 1.14x
  CHECK(level_for_size<3>(b, 0.0042).level == 9);  // 2.1 / 512 = 0.0041 <= 0.0042
  CHECK(level_for_size<3>(b, 0.0041).level == 10);
}


TEST_CASE("level_for_size in 2D: the same rule on the root square", "[size]") {
  Box<2> b;
  b.lo = Point<2>(0.0, 0.0);
  b.hi = Point<2>(3.0, 6.0);  // the default square 6.3 across
  const SizedLevel sl = level_for_size<2>(b, 0.01);  // 6.3 / 1024 = 0.00615 <= 0.01 < 6.3 / 512
  CHECK(sl.level == 10);
  CHECK(6.3 * sl.root_scale / 1024 == Approx(0.01).epsilon(1e-12));
  CHECK(level_for_size<2>(b, 6.3 / 256).root_scale == 1.0);
  CHECK(level_for_size<2>(b, 6.3 / 256).level == 8);
  CHECK(level_for_size<2>(b, 100.0).level == 1);  // no level under 1: a scale of 2 or more
  CHECK(level_for_size<2>(b, 100.0).root_scale == Approx(200.0 / 6.3));
}
