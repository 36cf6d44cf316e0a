#pragma once
// The cube root of the Escobar objective (escobar_objective.hpp), scalar and in lanes with the
// same IEEE operations in the same order. The algorithm is glibc's (sysdeps/ieee754/dbl-64/
// s_cbrt.c, unchanged since 1997: frexp, a degree-6 polynomial in the mantissa, one rational
// correction, a third of the exponent), so on glibc up to 2.40 at least (Debian 12 ships 2.36)
// cube_root equals std::cbrt bit for bit and the meshes do not change
// (tests/dim3/test_cube_root.cpp); with another libm it is still the same on every machine. The
// libm call a lane was 8% of fandisk L5's one-thread run (perf, session 29).

#include <cmath>
#include <cstdint>
#include <cstring>

#include "dim3/lanes.hpp"

namespace febemesh::dim3 {

// Vectors of four doubles passed to and from inlined functions without AVX (-Wpsabi).
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace cube_root_detail {

/// 2^(k/3), k = -2..2 (glibc's factor table).
inline constexpr double factor[5] = {1.0 / 1.5874010519681994748, 1.0 / 1.2599210498948731648, 1.0,
                                     1.2599210498948731648, 1.5874010519681994748};

/// The mantissa's cube root, xm in [0.5, 1), before the exponent's factor: glibc's polynomial and
/// its correction, in its order. T is double or a vector of doubles.
template <typename T> [[gnu::always_inline]] inline T mantissa_root(T xm) {
  const T u = (0.354895765043919860 +
               ((1.50819193781584896 +
                 ((-2.11499494167371287 +
                   ((2.44693122563534430 + ((-1.83469277483613086 + (0.784932344976639262 - 0.145263899385486377 * xm) * xm) * xm)) *
                    xm)) *
                  xm)) *
                xm));
  const T t2 = u * u * u;
  return u * (t2 + 2.0 * xm) / (2.0 * t2 + xm);
}

}  // namespace cube_root_detail

/// The cube root of x (glibc's algorithm; x + x for zero, infinities and NaN, as glibc).
inline double cube_root(double x) {
  if (x == 0.0 || !std::isfinite(x)) return x + x;
  int xe = 0;
  const double xm = std::frexp(std::fabs(x), &xe);
  const double ym = cube_root_detail::mantissa_root(xm) * cube_root_detail::factor[2 + xe % 3];
  return std::ldexp(x > 0.0 ? ym : -ym, xe / 3);
}

/// cube_root of every lane of x. Positive normal lanes take the vector path: frexp and ldexp are
/// exact bit operations there (the result ym 2^(xe/3) is normal), so every lane is cube_root's
/// number; any other lane (zero, subnormal, negative, not finite) is cube_root's own call.
template <int N> [[gnu::always_inline]] inline typename Lanes<N>::V cube_root_lanes(const typename Lanes<N>::V& x) {
  using V = typename Lanes<N>::V;
  V xm, factor, scale;
  int n_other = 0;
  for (int l = 0; l < N; ++l) {
    std::uint64_t bits;
    const double xl = x[l];
    std::memcpy(&bits, &xl, sizeof bits);
    const int e = static_cast<int>((bits >> 52) & 0x7ff);
    if ((bits >> 63) != 0 || e == 0 || e == 0x7ff) {
      ++n_other;
      xm[l] = 0.75, factor[l] = 1.0, scale[l] = 1.0;  // any normal lane; replaced below
      continue;
    }
    const std::uint64_t m = (bits & 0x000fffffffffffffULL) | (std::uint64_t{1022} << 52);  // frexp: [0.5, 1)
    double mant;
    std::memcpy(&mant, &m, sizeof mant);
    xm[l] = mant;
    const int xe = e - 1022;
    factor[l] = cube_root_detail::factor[2 + xe % 3];
    const std::uint64_t p = static_cast<std::uint64_t>(xe / 3 + 1023) << 52;  // 2^(xe/3), |xe/3| <= 341
    double two_k;
    std::memcpy(&two_k, &p, sizeof two_k);
    scale[l] = two_k;
  }
  V y = cube_root_detail::mantissa_root(xm) * factor * scale;
  if (n_other > 0)
    for (int l = 0; l < N; ++l) {
      const double xl = x[l];
      std::uint64_t bits;
      std::memcpy(&bits, &xl, sizeof bits);
      const int e = static_cast<int>((bits >> 52) & 0x7ff);
      if ((bits >> 63) != 0 || e == 0 || e == 0x7ff) y[l] = cube_root(xl);
    }
  return y;
}

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace febemesh::dim3
