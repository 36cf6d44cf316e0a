// escobar_objective: the lanes (EscobarLanes) equal the Eigen original bit for bit, on every
// lane, for every corner moving, inverted, flat and repeated-node tetrahedra, scales from 1e-6
// to 1e6 and delta 0 or not; two lanes (SSE2), and four compiled for AVX when the CPU has it (as
// the optimiser runs them).

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdint>

#include "dim3/escobar_objective.hpp"
#include "lane_testing.hpp"

using namespace febemesh;
using namespace febemesh::dim3;

namespace {

using P3 = Point<3>;
using test::bits;
using test::Rng;

struct Tally {
  long lanes = 0, mismatched = 0, inverted = 0;
};

/// Random tetrahedra N at a time, each with a random moving corner, evaluated by `objective`
/// at a random point and compared with escobar_objective there.
template <int N, class Objective> Tally compare(int rounds, Objective&& objective) {
  Rng g{20261205};
  Tally tally;
  for (int round = 0; round < rounds; ++round) {
    const double scale = std::array<double, 5>{1.0, 1e-6, 1e6, 37.5, 1e-2}[round % 5];
    const double len = scale * (0.05 + std::abs(g.uniform()));
    const double delta = round % 3 == 0 ? 0.0 : std::abs(g.uniform()) * std::array<double, 3>{1e-1, 1e-3, 1e-8}[round % 3];
    const P3 x = g.point(scale);
    EscobarLanes<N> lanes;
    std::array<double, N> want;
    for (int l = 0; l < N; ++l) {
      std::array<P3, 4> p = {g.point(scale), g.point(scale), g.point(scale), g.point(scale)};
      switch ((round + 3 * l) % 6) {
        case 0: p[3] = p[1] + 0.5 * (p[2] - p[1]); break;  // flat
        case 1: p[2] = p[1]; break;                         // repeated node
        default: break;
      }
      const int slot = (round / 2 + l) % 4;
      lanes.set_lane(l, p, slot);
      p[static_cast<std::size_t>(slot)] = x;
      want[static_cast<std::size_t>(l)] = escobar_objective(p, len, delta);
      const P3 e1 = p[1] - p[0], e2 = p[2] - p[0], e3 = p[3] - p[0];
      if (e1.dot(e2.cross(e3)) < 0) ++tally.inverted;
    }
    double out[N];
    objective(lanes, x, len, delta, out);
    for (int l = 0; l < N; ++l) {
      ++tally.lanes;
      if (bits(out[l]) != bits(want[static_cast<std::size_t>(l)])) ++tally.mismatched;
    }
  }
  return tally;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
[[gnu::target("avx")]] void objective_avx(const EscobarLanes<4>& lanes, const P3& x, double scale, double delta,
                                          double* out) {
  lanes.objective(x, scale, delta, out);
}
bool has_avx() { return __builtin_cpu_supports("avx"); }
#else
void objective_avx(const EscobarLanes<4>& lanes, const P3& x, double scale, double delta, double* out) {
  lanes.objective(x, scale, delta, out);
}
bool has_avx() { return false; }
#endif

}  // namespace

TEST_CASE("EscobarLanes<2> equals escobar_objective bit for bit", "[tet_optimize]") {
  const Tally t = compare<2>(100000, [](const EscobarLanes<2>& lanes, const P3& x, double scale, double delta,
                                        double* out) { lanes.objective(x, scale, delta, out); });
  CHECK(t.mismatched == 0);
  CHECK(t.lanes == 200000);
  CHECK(t.inverted > 50000);
}

TEST_CASE("EscobarLanes<4> equals escobar_objective bit for bit, with AVX and without", "[tet_optimize]") {
  const auto plain = [](const EscobarLanes<4>& lanes, const P3& x, double scale, double delta, double* out) {
    lanes.objective(x, scale, delta, out);
  };
  const Tally t = compare<4>(50000, plain);
  CHECK(t.mismatched == 0);
  CHECK(t.inverted > 50000);
  if (has_avx()) {
    const Tally a = compare<4>(50000, objective_avx);
    CHECK(a.mismatched == 0);
    CHECK(a.lanes == t.lanes);
  }
}
