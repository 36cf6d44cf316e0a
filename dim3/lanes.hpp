#pragma once
// N-double vectors (GCC and Clang vector extensions) and the lane operations the optimiser's
// kernels share (moving_tet.hpp's MovingTetLanes, escobar_objective.hpp's EscobarLanes): each
// operation is the scalar one lane by lane, so the kernels can equal their scalar twins bit for
// bit. With N = 2 one SSE2 instruction an operation; with N = 4 one AVX instruction when called
// from a function compiled for AVX (tet_optimize.cpp picks it at run time), else two SSE2 ones.

#include <cstdint>

namespace febemesh::dim3 {

// Four-double vectors passed between functions compiled without AVX change the ABI (GCC and
// Clang warn, -Wpsabi); every function that takes or returns one is inlined into its caller.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/// N-double vectors and their lane masks (all bits or none). Spelled out per N: GCC ignores
/// vector_size with a size that depends on a template parameter.
template <int N> struct Lanes;
template <> struct Lanes<2> {
  using V = double __attribute__((vector_size(16)));
  using M = std::int64_t __attribute__((vector_size(16)));
};
template <> struct Lanes<4> {
  using V = double __attribute__((vector_size(32)));
  using M = std::int64_t __attribute__((vector_size(32)));
};

/// Loads, broadcasts and selects on Lanes<N>; the kernels derive from it.
template <int N> struct LaneOps {
  static_assert(N == 2 || N == 4);
  using V = typename Lanes<N>::V;
  using M = typename Lanes<N>::M;

  [[gnu::always_inline]] static V load(const double* a) {
    V v;
    __builtin_memcpy(&v, a, sizeof v);
    return v;
  }
  [[gnu::always_inline]] static M load_mask(const std::int64_t* a) {
    M m;
    __builtin_memcpy(&m, a, sizeof m);
    return m;
  }
  [[gnu::always_inline]] static V splat(double a) {
    V v;
    for (int l = 0; l < N; ++l) v[l] = a;
    return v;
  }
  /// m ? a : b lane by lane.
  [[gnu::always_inline]] static V select(const M& m, const V& a, const V& b) {
    return reinterpret_cast<V>((m & reinterpret_cast<M>(a)) | (~m & reinterpret_cast<M>(b)));
  }
};

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace febemesh::dim3
