// moving_tet: the two-lane rank equals the scalar MovingTet::rank (its slow twin) bit for bit
// on every lane it does not hand back, and hands back exactly the lanes off the common case.

#include <catch2/catch.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "dim3/moving_tet.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P3 = Point<3>;

std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

/// Random points at several scales, with flat, near-flat, repeated and inverted tetrahedra.
struct Points {
  std::uint64_t s;
  double uniform() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) / double(1ULL << 53) - 0.5;
  }
  P3 point(double scale) { return scale * P3(uniform(), uniform(), uniform()); }
};

/// Compares lane by lane: equal bits on the common lanes, the scalar rank's special cases (a
/// negative rank or 0) on the odd ones.
void check_lanes(const std::array<MovingTet, 2>& m, const std::array<P3, 2>& x, const MovingTets2& batch,
                 int& n_common, int& n_odd) {
  const MovingTets2::V vx = {x[0][0], x[1][0]}, vy = {x[0][1], x[1][1]}, vz = {x[0][2], x[1][2]};
  MovingTets2::V r;
  MovingTets2::M odd;
  batch.rank(vx, vy, vz, r, odd);
  for (int l = 0; l < 2; ++l) {
    const double want = m[l].rank(x[l]);
    if (odd[l]) {
      ++n_odd;
      CHECK(want <= 0.0);
    } else {
      ++n_common;
      INFO("lane " << l << " scalar " << want << " batch " << r[l]);
      CHECK(bits(r[l]) == bits(want));
    }
  }
}

}  // namespace

TEST_CASE("MovingTets2::rank equals MovingTet::rank bit for bit", "[tet_optimize]") {
  Points g{20261202};
  const std::array<std::int32_t, 4> tet = {0, 1, 2, 3};
  int n_common = 0, n_odd = 0;
  for (int round = 0; round < 40000; ++round) {
    const double scale = std::array<double, 4>{1.0, 1e-3, 1e3, 37.5}[round % 4];
    std::array<MovingTet, 2> m;
    std::array<P3, 2> x;
    MovingTets2 batch;
    for (int l = 0; l < 2; ++l) {
      std::vector<P3> p = {g.point(scale), g.point(scale), g.point(scale), g.point(scale)};
      switch ((round + 3 * l) % 7) {
        case 0: p[3] = p[1] + 0.5 * (p[2] - p[1]); break;                      // flat opposite face
        case 1: p[2] = p[1]; break;                                             // repeated node
        case 2: p[3] = p[0] + (p[1] - p[0]) + 1e-9 * (p[2] - p[0]); break;      // near-flat
        default: break;
      }
      const std::int32_t v = (round / 2 + l) % 4;
      m[l].set(tet, v, p);
      batch.set_lane(l, m[l]);
      x[l] = (round + 2 * l) % 5 == 0 ? p[static_cast<std::size_t>(v)] : g.point(scale);
    }
    check_lanes(m, x, batch, n_common, n_odd);
    // One tetrahedron at two points, as the optimiser's gradients use it.
    MovingTets2 same;
    same.set_all(m[0]);
    check_lanes({m[0], m[0]}, x, same, n_common, n_odd);
  }
  CHECK(n_common > 50000);
  CHECK(n_odd > 10000);
}
