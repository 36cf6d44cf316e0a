#pragma once
// Escobar et al.'s untangling objective of a tetrahedron (tet_optimize.cpp's last resort on a
// tree): escobar_objective is the Eigen original (the slow twin); EscobarLanes evaluates N
// tetrahedra with one moving node at once, lane by lane with the same IEEE operations in the
// same order, so its values equal escobar_objective's bit for bit and the untangled mesh does
// not change. The objective was a fifth of fandisk L5's one-thread run (perf: its arithmetic
// 10.6%, the cube root 9.9%); the cube root is glibc's algorithm in lanes (cube_root.hpp).
//
// The order Eigen 3.4 gives (found by comparing bits over 2 x 10^6 random tetrahedra, and
// checked by tests/dim3/test_escobar_objective.cpp): the product S = A W^-1 sums each
// coefficient as (a_i0 w_0j + a_i1 w_1j) + a_i2 w_2j except the last, (2, 2), which is
// a_20 w_02 + (a_21 w_12 + a_22 w_22); det S is Eigen's cofactor sum; |S|^2 adds the nine
// squares in pairs, (((x0 + x2) + (x4 + x6)) + ((x1 + x3) + (x5 + x7))) + x8 (column-major
// index). No multiply-add may be fused (the build targets no FMA).

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/LU>

#include "core/box.hpp"  // Point
#include "dim3/cube_root.hpp"
#include "dim3/lanes.hpp"

namespace febemesh::dim3 {

/// The inverse of the regular tetrahedron's edge matrix (columns (1,0,0), (1/2, sqrt3/2, 0),
/// (1/2, sqrt3/6, sqrt(2/3))).
inline const Eigen::Matrix3d& escobar_w_inv() {
  static const Eigen::Matrix3d w_inv = [] {
    Eigen::Matrix3d w;
    w << 1.0, 0.5, 0.5, 0.0, std::sqrt(3.0) / 2.0, std::sqrt(3.0) / 6.0, 0.0, 0.0, std::sqrt(2.0 / 3.0);
    return Eigen::Matrix3d(w.inverse());
  }();
  return w_inv;
}

/// Escobar et al.'s objective of the tetrahedron p: |S|^2 / (3 h(s)^(2/3)), S its Jacobian
/// against the regular tetrahedron of edge `scale`, s = det S and h(s) = (s + sqrt(s^2 + 4
/// delta^2)) / 2 > 0, so that the sum over a node's tetrahedra is finite and smooth across
/// inverted ones, and its minimum lies where they are positive.
inline double escobar_objective(const std::array<Point<3>, 4>& p, double scale, double delta) {
  const Eigen::Matrix3d& w_inv = escobar_w_inv();
  Eigen::Matrix3d a;
  a.col(0) = (p[1] - p[0]) / scale;
  a.col(1) = (p[2] - p[0]) / scale;
  a.col(2) = (p[3] - p[0]) / scale;
  const Eigen::Matrix3d sm = a * w_inv;
  const double sigma = sm.determinant();
  const double hs = 0.5 * (sigma + std::sqrt(sigma * sigma + 4.0 * delta * delta));
  return sm.squaredNorm() / (3.0 * cube_root(hs * hs));
}

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/// N tetrahedra sharing one moving node, stored coordinate by coordinate: corner k of lane l
/// is the moving node where moving[k] has lane l set, else fixed[k][.][l].
template <int N> struct EscobarLanes : private LaneOps<N> {
  using typename LaneOps<N>::V;
  using typename LaneOps<N>::M;

  alignas(8 * N) double fixed[4][3][N];
  alignas(8 * N) std::int64_t moving[4][N];

  /// Lane `lane` := tetrahedron p, whose corner `slot` is the moving node (p[slot] unused).
  void set_lane(int lane, const std::array<Point<3>, 4>& p, int slot) {
    for (int k = 0; k < 4; ++k) {
      for (int c = 0; c < 3; ++c) fixed[k][c][lane] = k == slot ? 0.0 : p[k][c];
      moving[k][lane] = k == slot ? -1 : 0;
    }
  }

  /// escobar_objective of every lane with the moving node at x, into out[0..N).
  [[gnu::always_inline]] void objective(const Point<3>& x, double scale, double delta, double* out) const {
    V p[4][3];
    for (int k = 0; k < 4; ++k) {
      const M m = load_mask(moving[k]);
      for (int c = 0; c < 3; ++c) p[k][c] = select(m, splat(x[c]), load(fixed[k][c]));
    }
    // A (row i, column j) = (p[j + 1][i] - p[0][i]) / scale.
    V a[3][3];
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) a[i][j] = (p[j + 1][i] - p[0][i]) / scale;
    const Eigen::Matrix3d& w = escobar_w_inv();
    V s[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] = (a[i][0] * w(0, j) + a[i][1] * w(1, j)) + a[i][2] * w(2, j);
    s[2][2] = a[2][0] * w(0, 2) + (a[2][1] * w(1, 2) + a[2][2] * w(2, 2));
    const V sigma = (s[0][0] * (s[1][1] * s[2][2] - s[1][2] * s[2][1]) - s[0][1] * (s[1][0] * s[2][2] - s[1][2] * s[2][0])) +
                    s[0][2] * (s[1][0] * s[2][1] - s[1][1] * s[2][0]);
    V sq[9];
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) sq[3 * j + i] = s[i][j] * s[i][j];
    const V norm2 = (((sq[0] + sq[2]) + (sq[4] + sq[6])) + ((sq[1] + sq[3]) + (sq[5] + sq[7]))) + sq[8];
    const V under = sigma * sigma + splat(4.0 * delta * delta);
    V root = splat(0.0);
    for (int l = 0; l < N; ++l) root[l] = std::sqrt(under[l]);
    const V hs = 0.5 * (sigma + root);
    const V hs2 = hs * hs;
    const V cube = cube_root_lanes<N>(hs2);
    const V r = norm2 / (3.0 * cube);
    __builtin_memcpy(out, &r, sizeof r);
  }

 private:
  using LaneOps<N>::load;
  using LaneOps<N>::load_mask;
  using LaneOps<N>::splat;
  using LaneOps<N>::select;
};

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace febemesh::dim3
