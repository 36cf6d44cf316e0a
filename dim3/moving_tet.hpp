#pragma once
// The tet optimiser's inner kernel (tet_optimize.cpp): the search rank of a tetrahedron as one
// of its nodes, v, moves. MovingTet is the scalar original (the slow twin); MovingTetLanes ranks
// N tetrahedra, or one at N points, at once with the same operations lane by lane (GCC and
// Clang vector extensions), so its ranks equal MovingTet::rank's bit for bit and the
// optimiser's mesh does not change. Lanes off the common case (inverted, flat or degenerate
// tetrahedra) take its other branches in lanes as well; only NaN ranks come back for it to redo.
//
// Bit equality needs every lane to do MovingTet::rank's IEEE operations in its order: Eigen
// sums a 3-vector's dot product and squared norm left to right, ((x0 + x1) + x2), and no
// multiply-add may be fused (the build targets no FMA; -ffp-contract cannot fuse without it).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/box.hpp"  // Point
#include "dim3/lanes.hpp"

namespace febemesh::dim3 {

/// A tetrahedron seen from one of its nodes, v: the other three in an order that keeps the
/// orientation with v first, and what does not depend on where v is. rank(x) is
/// tet_search_rank of the tetrahedron with v at x (the same formula, fewer operations).
struct MovingTet {
  Point<3> q1, q2, q3, n0;  // n0: outward normal of the face opposite v
  double inv0 = 0.0;        // 1 / |n0|^2, 0 for a zero-area face
  double l2_fixed = 0.0;    // squared lengths of the three edges away from v
  /// t: the tetrahedron's nodes in Gmsh order, one of them v.
  void set(const std::array<std::int32_t, 4>& t, std::int32_t v, const std::vector<Point<3>>& pts) {
    // Even permutations that bring local node k first.
    static constexpr int order[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
    const int k = t[0] == v ? 0 : t[1] == v ? 1 : t[2] == v ? 2 : 3;
    q1 = pts[t[order[k][1]]], q2 = pts[t[order[k][2]]], q3 = pts[t[order[k][3]]];
    const Point<3> bc = q2 - q1, bd = q3 - q1, cd = q3 - q2;
    // The normal's norm from the registers, before it is stored: read back from the member, a
    // two-double load spanning two stores missed the store buffer (perf: 9% of relax's own
    // samples on fandisk L5 at that one load). The same operations, so the same number.
    const Point<3> n = bc.cross(bd);
    const double s0 = n.squaredNorm();
    n0 = n;
    inv0 = s0 > 0 ? 1.0 / s0 : 0.0;
    l2_fixed = bc.squaredNorm() + bd.squaredNorm() + cd.squaredNorm();
  }
  double rank(const Point<3>& x) const {
    using P3 = Point<3>;
    const P3 ab = q1 - x, ac = q2 - x, ad = q3 - x;
    const P3 n1 = ad.cross(ac), n2 = ab.cross(ad), n3 = ac.cross(ab);
    const double v6 = -ab.dot(n1);
    const double l2 = (ab.squaredNorm() + ac.squaredNorm() + ad.squaredNorm() + l2_fixed) / 6.0;
    if (l2 <= 0) return -2.0;
    if (!(v6 > 0 && 2.0 * v6 * v6 > 1e-18 * l2 * l2 * l2) || !(inv0 > 0))
      return std::min(std::sqrt(2.0) * v6 / (l2 * std::sqrt(l2)), 0.0) - 1.0;
    const double s1 = n1.squaredNorm(), s2 = n2.squaredNorm(), s3 = n3.squaredNorm();
    if (!(s1 > 0 && s2 > 0 && s3 > 0)) return 0.0;
    const double i1 = 1.0 / s1, i2 = 1.0 / s2, i3 = 1.0 / s3;
    const auto term = [](double dd, double inv) { return dd * std::abs(dd) * inv; };
    double best = term(-n0.dot(n1), inv0 * i1);
    best = std::max(best, term(-n0.dot(n2), inv0 * i2));
    best = std::max(best, term(-n0.dot(n3), inv0 * i3));
    best = std::max(best, term(-n1.dot(n2), i1 * i2));
    best = std::max(best, term(-n1.dot(n3), i1 * i3));
    best = std::max(best, term(-n2.dot(n3), i2 * i3));
    return 1.0 - std::clamp(best, -1.0, 1.0);
  }
};

// Four-double vectors passed between functions compiled without AVX change the ABI (GCC and
// Clang warn, -Wpsabi); every function here that takes or returns one is inlined into its
// caller.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/// N lanes of MovingTet (N tetrahedra, or one tetrahedron N times), stored field by field.
/// rank() works on N-double vectors: with N = 2 one SSE2 instruction per operation; with N = 4
/// one AVX instruction when called from a function compiled for AVX (tet_optimize.cpp picks it
/// at run time), else two SSE2 ones.
template <int N> struct MovingTetLanes : private LaneOps<N> {
  static constexpr int n_lanes = N;
  using typename LaneOps<N>::V;
  using typename LaneOps<N>::M;

  alignas(8 * N) double q1[3][N], q2[3][N], q3[3][N], n0[3][N], inv0[N], l2_fixed[N];

  /// Lane `lane` := m.
  void set_lane(int lane, const MovingTet& m) {
    for (int d = 0; d < 3; ++d)
      q1[d][lane] = m.q1[d], q2[d][lane] = m.q2[d], q3[d][lane] = m.q3[d], n0[d][lane] = m.n0[d];
    inv0[lane] = m.inv0, l2_fixed[lane] = m.l2_fixed;
  }
  /// Every lane := m.
  void set_all(const MovingTet& m) {
    for (int l = 0; l < N; ++l) set_lane(l, m);
  }

  /// MovingTet::rank of lane l at (x[l], y[l], z[l]) into out[l], NaN where MovingTet::rank's
  /// is NaN (callers redo those with it: that changes nothing). Inverted, flat and degenerate
  /// lanes take MovingTet::rank's other branches in lanes too (off_common), only when some lane
  /// needs them: the untangling's tetrahedra are often inverted, and each such lane was one
  /// scalar call more (MovingTet::rank: 6.3% of fandisk L5's one-thread run, perf).
  [[gnu::always_inline]] void rank(const double* x, const double* y, const double* z, double* out) const {
    const V px = load(x), py = load(y), pz = load(z);
    const V ab[3] = {load(q1[0]) - px, load(q1[1]) - py, load(q1[2]) - pz};
    const V ac[3] = {load(q2[0]) - px, load(q2[1]) - py, load(q2[2]) - pz};
    const V ad[3] = {load(q3[0]) - px, load(q3[1]) - py, load(q3[2]) - pz};
    V n1[3], n2[3], n3[3];
    cross(ad, ac, n1);
    cross(ab, ad, n2);
    cross(ac, ab, n3);
    const V v6 = -dot(ab, n1);
    const V l2 = (((dot(ab, ab) + dot(ac, ac)) + dot(ad, ad)) + load(l2_fixed)) / 6.0;
    const V s1 = dot(n1, n1), s2 = dot(n2, n2), s3 = dot(n3, n3);
    const V in0 = load(inv0);
    const V zero = splat(0.0);
    // The common case, as MovingTet::rank's tests; NaN fails every comparison, as there.
    const M ok = (l2 > zero) & (v6 > zero) & ((2.0 * v6) * v6 > ((1e-18 * l2) * l2) * l2) & (in0 > zero) &
                 (s1 > zero) & (s2 > zero) & (s3 > zero);
    const V one = splat(1.0);
    const V i1 = one / s1, i2 = one / s2, i3 = one / s3;
    const V m0[3] = {load(n0[0]), load(n0[1]), load(n0[2])};
    V best = term(-dot(m0, n1), in0 * i1);
    best = max(best, term(-dot(m0, n2), in0 * i2));
    best = max(best, term(-dot(m0, n3), in0 * i3));
    best = max(best, term(-dot(n1, n2), i1 * i2));
    best = max(best, term(-dot(n1, n3), i1 * i3));
    best = max(best, term(-dot(n2, n3), i2 * i3));
    // std::clamp(best, -1, 1): best < -1 ? -1 : 1 < best ? 1 : best.
    best = select(best < -one, -one, select(one < best, one, best));
    V r = one - best;
    bool all_ok = true;
    for (int l = 0; l < N; ++l) all_ok = all_ok && ok[l] != 0;
    if (!all_ok) r = select(ok, r, off_common(v6, l2, in0, s1, s2, s3));
    __builtin_memcpy(out, &r, sizeof r);
  }

 private:
  /// MovingTet::rank's branches before the common case, lane by lane in its order: l2 <= 0
  /// gives -2; a volume not clearly positive or a zero-area face opposite v gives
  /// min(sqrt2 v6 / l2^1.5, 0) - 1; another zero-area face gives 0; NaN elsewhere (the
  /// common case, which the caller keeps).
  [[gnu::always_inline]] static V off_common(const V& v6, const V& l2, const V& in0, const V& s1, const V& s2,
                                             const V& s3) {
    const V zero = splat(0.0), one = splat(1.0);
    const M low = l2 <= zero;
    const M not_positive = ~((v6 > zero) & ((2.0 * v6) * v6 > ((1e-18 * l2) * l2) * l2) & (in0 > zero));
    const M zero_face = ~((s1 > zero) & (s2 > zero) & (s3 > zero));
    V root = zero;
    for (int l = 0; l < N; ++l) root[l] = std::sqrt(l2[l]);
    // std::min(a, 0.0) = 0.0 < a ? 0.0 : a.
    const V a = (std::sqrt(2.0) * v6) / (l2 * root);
    const V r_inverted = select(zero < a, zero, a) - one;
    return select(low, splat(-2.0),
                  select(not_positive, r_inverted,
                         select(zero_face, zero, splat(std::numeric_limits<double>::quiet_NaN()))));
  }
  using LaneOps<N>::load;
  using LaneOps<N>::splat;
  using LaneOps<N>::select;
  [[gnu::always_inline]] static V dot(const V (&a)[3], const V (&b)[3]) {
    return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
  }
  [[gnu::always_inline]] static void cross(const V (&a)[3], const V (&b)[3], V (&c)[3]) {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  }
  /// std::max(a, b) = a < b ? b : a (ties and NaN keep a): one maxpd.
  [[gnu::always_inline]] static V max(const V& a, const V& b) { return a < b ? b : a; }
  /// dd * |dd| * inv, |dd| by clearing the sign bit (std::abs).
  [[gnu::always_inline]] static V term(const V& dd, const V& inv) {
    const V abs_dd = reinterpret_cast<V>(reinterpret_cast<M>(dd) & (M{} + INT64_MAX));
    return dd * abs_dd * inv;
  }
};

#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

}  // namespace febemesh::dim3
