// cube_root.hpp: the lanes equal the scalar cube_root bit for bit (two lanes, and four compiled
// for AVX when the CPU has it), on positive normal numbers of every exponent, the Escobar
// objective's range, and the lanes that fall back (zero, subnormal, negative, infinite, NaN);
// and cube_root is glibc's cbrt: the same bits where the C library is glibc up to 2.40 (the
// meshes then do not change), else within one unit in the last place.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "dim3/cube_root.hpp"
#include "lane_testing.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
using test::bits;

namespace {

#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

template <int N> [[gnu::always_inline]] inline void roots(const double* in, double* out) {
  typename Lanes<N>::V v;
  std::memcpy(&v, in, sizeof v);
  const typename Lanes<N>::V r = cube_root_lanes<N>(v);
  std::memcpy(out, &r, sizeof r);
}

void roots2(const double* in, double* out) { roots<2>(in, out); }

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target("avx")]] void roots4(const double* in, double* out) { roots<4>(in, out); }
bool has_avx() { return __builtin_cpu_supports("avx"); }
#else
void roots4(const double* in, double* out) { roots<4>(in, out); }
bool has_avx() { return false; }
#endif

/// Inputs: random bit patterns of positive numbers (every exponent, subnormals included), values
/// spread over 10^-30..10^30 as the objective's h^2 takes, and the special values.
std::vector<double> inputs(std::size_t n) {
  test::Rng rng{12345};
  std::vector<double> x;
  x.reserve(n + 16);
  for (const double s : {0.0, -0.0, 4.9e-324, 2.2e-308, 1.0, 8.0, 27.0, -8.0, 0.125, 1e300,
                         std::numeric_limits<double>::max(), std::numeric_limits<double>::infinity(),
                         -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    x.push_back(s);
  for (std::size_t i = 0; x.size() < n; ++i) {
    if (i % 2 == 0) {
      std::uint64_t b = 0;
      for (int k = 0; k < 4; ++k) b = (b << 16) ^ static_cast<std::uint64_t>((rng.uniform() + 0.5) * 65536.0);
      b &= 0x7fffffffffffffffULL;
      if ((b >> 52) == 0x7ff) continue;  // not finite: among the special values
      double d;
      std::memcpy(&d, &b, sizeof d);
      x.push_back(d);
    } else {
      x.push_back((rng.uniform() + 0.5) * std::pow(10.0, 60.0 * rng.uniform()));
    }
  }
  return x;
}

bool same(double a, double b) { return bits(a) == bits(b) || (std::isnan(a) && std::isnan(b)); }

}  // namespace

TEST_CASE("cube_root_lanes equals cube_root bit for bit, with AVX and without", "[tet_optimize]") {
  const std::vector<double> x = inputs(400000);
  std::size_t n2 = 0, n4 = 0, bad2 = 0, bad4 = 0;
  for (std::size_t i = 0; i + 4 <= x.size(); i += 4) {
    double out[4];
    roots2(&x[i], out);
    roots2(&x[i + 2], out + 2);
    for (int l = 0; l < 4; ++l, ++n2) bad2 += same(out[l], cube_root(x[i + l])) ? 0 : 1;
    if (!has_avx()) continue;
    roots4(&x[i], out);
    for (int l = 0; l < 4; ++l, ++n4) bad4 += same(out[l], cube_root(x[i + l])) ? 0 : 1;
  }
  CHECK(n2 == 400000);
  CHECK(bad2 == 0);
  CHECK(bad4 == 0);
  if (has_avx()) CHECK(n4 == 400000);
}

TEST_CASE("cube_root is glibc's cbrt", "[tet_optimize]") {
  const std::vector<double> x = inputs(400000);
  std::size_t differ = 0, over_ulp = 0;
  for (const double v : x) {
    const double a = cube_root(v), b = std::cbrt(v);
    if (same(a, b)) continue;
    ++differ;
    if (std::abs(a - b) > std::abs(std::nextafter(b, 0.0) - b)) ++over_ulp;
  }
  CHECK(over_ulp == 0);
#if defined(__GLIBC__) && (__GLIBC__ == 2 && __GLIBC_MINOR__ <= 40)
  CHECK(differ == 0);
#endif
  // Roots of cubes, to a unit in the last place (glibc's cbrt(-27) is not exactly -3).
  const double eps = std::numeric_limits<double>::epsilon();
  CHECK(std::abs(cube_root(8.0) - 2.0) <= 2.0 * eps);
  CHECK(std::abs(cube_root(-27.0) + 3.0) <= 3.0 * eps);
  CHECK(std::abs(cube_root(1e-300) - 1e-100) <= 1e-100 * eps);
  CHECK(bits(cube_root(0.0)) == bits(0.0));
  CHECK(bits(cube_root(-0.0)) == bits(-0.0));
}
