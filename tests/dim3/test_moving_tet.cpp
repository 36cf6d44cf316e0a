// moving_tet: the lanes' rank equals the scalar MovingTet::rank (its slow twin) bit for bit on
// every lane, inverted, flat and degenerate tetrahedra included, and hands back (NaN) only lanes
// whose scalar rank is NaN; two lanes (SSE2), and four compiled for AVX when the CPU has it (as
// the optimiser runs them).

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "dim3/moving_tet.hpp"
#include "lane_testing.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P3 = Point<3>;
using test::bits;
using test::Rng;

struct Tally {
  int common = 0;      ///< lanes ranked above 0
  int off_common = 0;  ///< lanes ranked at or below 0 (inverted, flat, degenerate), not handed back
  int no_length = 0;   ///< of them, lanes whose edges are all zero (rank -2)
  int odd = 0;         ///< lanes handed back (NaN)
  int mismatched = 0;
};

/// Random tetrahedra at several scales, with flat, near-flat, repeated and inverted ones, and
/// random points: N of them at a time, and one of them at N points; calls `ranks(lanes, x, y,
/// z, out)` (NaN in the lanes handed back) and compares with MovingTet::rank.
template <int N, class Ranks> Tally compare_lanes(int rounds, Ranks&& ranks) {
  Rng g{20261202};
  const std::array<std::int32_t, 4> tet = {0, 1, 2, 3};
  Tally tally;
  for (int round = 0; round < rounds; ++round) {
    const double scale = std::array<double, 4>{1.0, 1e-3, 1e3, 37.5}[round % 4];
    std::array<MovingTet, N> m;
    double x[3][N];
    MovingTetLanes<N> lanes;
    for (int l = 0; l < N; ++l) {
      std::vector<P3> p = {g.point(scale), g.point(scale), g.point(scale), g.point(scale)};
      switch ((round + 3 * l) % 7) {
        case 0: p[3] = p[1] + 0.5 * (p[2] - p[1]); break;                  // flat opposite face
        case 1: p[2] = p[1]; break;                                         // repeated node
        case 2: p[3] = p[0] + (p[1] - p[0]) + 1e-9 * (p[2] - p[0]); break;  // near-flat
        case 3: p[1] = p[2] = p[3] = p[0]; break;                           // one point (l2 = 0 at p[v])
        default: break;
      }
      const std::int32_t v = (round / 2 + l) % 4;
      m[l].set(tet, v, p);
      lanes.set_lane(l, m[l]);
      const P3 at = (round + 2 * l) % 5 == 0 ? p[static_cast<std::size_t>(v)] : g.point(scale);
      for (int c = 0; c < 3; ++c) x[c][l] = at[c];
    }
    for (const bool same : {false, true}) {
      if (same) lanes.set_all(m[0]);
      double out[N];
      ranks(lanes, x[0], x[1], x[2], out);
      for (int l = 0; l < N; ++l) {
        const double want = (same ? m[0] : m[l]).rank(P3(x[0][l], x[1][l], x[2][l]));
        if (std::isnan(out[l])) {
          ++tally.odd;
          if (!std::isnan(want)) ++tally.mismatched;  // handed back only where the scalar rank is NaN
        } else {
          ++(out[l] > 0.0 ? tally.common : tally.off_common);
          if (out[l] == -2.0) ++tally.no_length;
          if (bits(out[l]) != bits(want)) ++tally.mismatched;
        }
      }
    }
  }
  return tally;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
[[gnu::target("avx")]] void ranks_avx(const MovingTetLanes<4>& lanes, const double* x, const double* y, const double* z,
                                      double* out) {
  lanes.rank(x, y, z, out);
}
bool has_avx() { return __builtin_cpu_supports("avx"); }
#else
void ranks_avx(const MovingTetLanes<4>& lanes, const double* x, const double* y, const double* z, double* out) {
  lanes.rank(x, y, z, out);
}
bool has_avx() { return false; }
#endif

}  // namespace

TEST_CASE("MovingTetLanes<2>::rank equals MovingTet::rank bit for bit", "[tet_optimize]") {
  const Tally t = compare_lanes<2>(40000, [](const MovingTetLanes<2>& lanes, const double* x, const double* y,
                                             const double* z, double* out) { lanes.rank(x, y, z, out); });
  CHECK(t.mismatched == 0);
  CHECK(t.common > 50000);
  CHECK(t.off_common > 10000);
  CHECK(t.no_length > 100);
}

TEST_CASE("MovingTetLanes<4>::rank equals MovingTet::rank bit for bit, with AVX and without", "[tet_optimize]") {
  const auto plain = [](const MovingTetLanes<4>& lanes, const double* x, const double* y, const double* z,
                        double* out) { lanes.rank(x, y, z, out); };
  const Tally t = compare_lanes<4>(20000, plain);
  CHECK(t.mismatched == 0);
  CHECK(t.common > 50000);
  CHECK(t.off_common > 10000);
  CHECK(t.no_length > 100);
  if (has_avx()) {
    const Tally a = compare_lanes<4>(20000, ranks_avx);
    CHECK(a.mismatched == 0);
    CHECK(a.common == t.common);
    CHECK(a.off_common == t.off_common);
  }
}
