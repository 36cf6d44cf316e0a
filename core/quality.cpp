// Verdict quality measures, generic over the ambient dimension.

#include "core/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "core/error.hpp"
#include "core/mesh_topology.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

namespace {

constexpr double rad_to_deg = 180.0 / std::numbers::pi;
constexpr double inf = std::numeric_limits<double>::infinity();

/// Corner c with its neighbours (a, b[, d]) in right-handed order for a positive element.
struct Corner {
  int c, a, b, d;
};
constexpr Corner tri_corners[] = {{0, 1, 2, -1}, {1, 2, 0, -1}, {2, 0, 1, -1}};
constexpr Corner quad_corners[] = {{0, 1, 3, -1}, {1, 2, 0, -1}, {2, 3, 1, -1}, {3, 0, 2, -1}};
constexpr Corner tet_corners[] = {{0, 1, 2, 3}, {1, 2, 0, 3}, {2, 0, 1, 3}, {3, 0, 2, 1}};
constexpr Corner hex_corners[] = {{0, 1, 3, 4}, {1, 2, 0, 5}, {2, 3, 1, 6}, {3, 0, 2, 7},
                                  {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}};
constexpr Corner prism_corners[] = {{0, 1, 2, 3}, {1, 2, 0, 4}, {2, 0, 1, 5},
                                    {3, 5, 4, 0}, {4, 3, 5, 1}, {5, 4, 3, 2}};
constexpr Corner pyramid_corners[] = {{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}};

std::span<const Corner> corners(ElemType t) {
  switch (t) {
    case ElemType::Line2: return {};
    case ElemType::Tri3: return tri_corners;
    case ElemType::Quad4: return quad_corners;
    case ElemType::Tet4: return tet_corners;
    case ElemType::Hex8: return hex_corners;
    case ElemType::Prism6: return prism_corners;
    case ElemType::Pyramid5: return pyramid_corners;
  }
  return {};
}

double normalisation(ElemType t) {
  switch (t) {
    case ElemType::Tri3:
    case ElemType::Prism6: return 2.0 / std::sqrt(3.0);
    case ElemType::Tet4:
    case ElemType::Pyramid5: return std::sqrt(2.0);
    default: return 1.0;
  }
}

/// Signed (Dim == 2) or unsigned (Dim == 3) area of the parallelogram spanned by a and b.
template <int Dim> double cross2(const Point<Dim>& a, const Point<Dim>& b) {
  if constexpr (Dim == 2) {
    return a.x() * b.y() - a.y() * b.x();
  } else {
    return a.cross(b).norm();
  }
}

template <int Dim> double det3(const Point<Dim>& a, const Point<Dim>& b, const Point<Dim>& c) {
  if constexpr (Dim == 3) {
    return a.dot(b.cross(c));
  } else {
    MESH_ASSERT(false, "3D element in a 2D mesh");
    (void)a, (void)b, (void)c;
    return 0.0;
  }
}

/// Corner Jacobian and the product of its edge lengths.
template <int Dim> std::pair<double, double> corner_jacobian(ElemType t, const Corner& k, std::span<const Point<Dim>> p) {
  const Point<Dim> a = p[k.a] - p[k.c];
  const Point<Dim> b = p[k.b] - p[k.c];
  if (dimension(t) == 2) return {cross2<Dim>(a, b), a.norm() * b.norm()};
  const Point<Dim> d = p[k.d] - p[k.c];
  return {det3<Dim>(a, b, d), a.norm() * b.norm() * d.norm()};
}

template <int Dim> double angle_deg(const Point<Dim>& a, const Point<Dim>& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 0.0;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * rad_to_deg;
}

/// The cosine of each corner angle of a polygon (Tri3, Quad4) in corners(t)'s order, as
/// angle_deg takes it: the angle is angle_of_key(key); a corner with a zero edge has key 1
/// (angle_deg's 0 degrees). Returns the number of corners.
template <int Dim> int polygon_corner_keys(ElemType t, std::span<const Point<Dim>> p, double* key) {
  int n = 0;
  for (const Corner& k : corners(t)) {
    const Point<Dim> a = p[k.a] - p[k.c], b = p[k.b] - p[k.c];
    const double na = a.norm(), nb = b.norm();
    key[n++] = na == 0.0 || nb == 0.0 ? 1.0 : std::clamp(a.dot(b) / (na * nb), -1.0, 1.0);
  }
  return n;
}
double angle_of_key(double key) { return std::acos(key) * rad_to_deg; }

/// Newell normal of facet f (area-weighted, outward).
Point<3> facet_normal(ElemType t, int f, std::span<const Point<3>> p) {
  const auto local = facet_local_nodes(t, f);
  Point<3> n = Point<3>::Zero();
  const Point<3>& o = p[local[0]];
  for (std::size_t i = 1; i + 1 < local.size(); ++i) n += (p[local[i]] - o).cross(p[local[i + 1]] - o);
  return 0.5 * n;
}

/// Gmsh's tetrahedron facets (mesh_topology's table): facet_normal and signed_measure of a Tet4
/// with the same operations on constant indices (no table look-up per facet; issue 8).
constexpr int tet_facet_nodes[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {3, 1, 2}};

Point<3> tet_facet_normal(int f, std::span<const Point<3>> p) {
  const int* l = tet_facet_nodes[f];
  Point<3> n = Point<3>::Zero();
  const Point<3>& o = p[l[0]];
  n += (p[l[1]] - o).cross(p[l[2]] - o);
  return 0.5 * n;
}

template <int Dim> double tet_signed_measure(std::span<const Point<Dim>> p) {
  if constexpr (Dim == 3) {
    // The three facets through node 0 add exact zeros below (one of their vectors is
    // p[0] - p[0]), so only facet {3, 1, 2} counts: the same operations on it give the same
    // number (the zeros' sums are +0, as 0.0 + w is here), a quarter of the work (this was 4.8%
    // of sphere966 L6's run on one thread). Not where a product could overflow to infinity
    // (then 0 * inf is NaN in the loop).
    const Point<3> a = p[3] - p[0], b = p[1] - p[0], c = p[2] - p[0];
    const double big = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff()});
    if (big < 1e100) {
      double w = 0.0;
      w += a.dot(b.cross(c));
      return (0.0 + w) / 6.0;
    }
    double v = 0.0;
    for (int f = 0; f < 4; ++f) {
      const int* l = tet_facet_nodes[f];
      double w = 0.0;
      const Point<3> a = p[l[0]] - p[0], b = p[l[1]] - p[0], c = p[l[2]] - p[0];
      w += a.dot(b.cross(c));
      v += w;
    }
    return v / 6.0;
  } else {
    MESH_ASSERT(false, "3D element in a 2D mesh");
    (void)p;
    return 0.0;
  }
}

bool facet_has_edge(std::span<const int> facet, int a, int b) {
  const std::size_t n = facet.size();
  for (std::size_t i = 0; i < n; ++i) {
    const int u = facet[i], w = facet[(i + 1) % n];
    if ((u == a && w == b) || (u == b && w == a)) return true;
  }
  return false;
}

/// Dihedral angles (degrees) of a 3D element at each of its edges: min and max.
std::pair<double, double> dihedral_range(ElemType t, std::span<const Point<3>> p) {
  double lo = inf, hi = -inf;
  for (int e = 0; e < n_edges(t); ++e) {
    const auto [a, b] = edge_local_nodes(t, e);
    int faces[2] = {-1, -1};
    int found = 0;
    for (int f = 0; f < n_facets(t) && found < 2; ++f)
      if (facet_has_edge(facet_local_nodes(t, f), a, b)) faces[found++] = f;
    MESH_ASSERT(found == 2, "edge " << e << " of " << name(t));
    const double between_normals = angle_deg<3>(facet_normal(t, faces[0], p), facet_normal(t, faces[1], p));
    const double dihedral = 180.0 - between_normals;
    lo = std::min(lo, dihedral);
    hi = std::max(hi, dihedral);
  }
  return {lo, hi};
}

template <int Dim> std::pair<double, double> edge_length_range(ElemType t, std::span<const Point<Dim>> p, double* sum = nullptr) {
  double lo = inf, hi = 0.0, s = 0.0;
  for (int e = 0; e < n_edges(t); ++e) {
    const auto [a, b] = edge_local_nodes(t, e);
    const double l = (p[b] - p[a]).norm();
    lo = std::min(lo, l);
    hi = std::max(hi, l);
    s += l;
  }
  if (sum != nullptr) *sum = s;
  return {lo, hi};
}

template <int Dim> double tet_radius_ratio(std::span<const Point<Dim>> p) {
  if constexpr (Dim == 3) {
    const Point<3> a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const double det = a.dot(b.cross(c));
    if (det <= 0.0) return inf;
    const Point<3> num = a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b);
    const double circum = num.norm() / (2.0 * det);
    double area = 0.0;
    for (int f = 0; f < 4; ++f) area += facet_normal(ElemType::Tet4, f, p).norm();
    const double in = det / (2.0 * area);  // r = 3V / A with V = det / 6
    return circum / (3.0 * in);
  } else {
    (void)p;
    return 0.0;
  }
}

/// The corner Jacobians of a tetrahedron, corners of tet_corners in their order.
/// Corner (c; a, b, d): J = (a - c) . ((b - c) x (d - c)).
std::array<double, 4> tet_corner_dets(std::span<const Point<3>> p) {
  const Point<3> e01 = p[1] - p[0], e02 = p[2] - p[0], e03 = p[3] - p[0], e12 = p[2] - p[1], e13 = p[3] - p[1],
                 e23 = p[3] - p[2];
  return {det3<3>(e01, e02, e03), det3<3>(e12, Point<3>(p[0] - p[1]), e13),
          det3<3>(Point<3>(p[0] - p[2]), Point<3>(p[1] - p[2]), e23),
          det3<3>(Point<3>(p[0] - p[3]), Point<3>(p[2] - p[3]), Point<3>(p[1] - p[3]))};
}

/// jacobians() of a tetrahedron: the corners of tet_corners in their order, with the same
/// numbers, but each of the six edge lengths computed once (|p - q| and |q - p| are the same
/// bits), not once per corner that uses it (the smoothing guard's hot path).
/// `longest`, when given: the longest edge, as edge_length_range's maximum (a vector and its
/// negation have the same norm, and a maximum does not depend on the order).
std::pair<double, double> tet_jacobians(std::span<const Point<3>> p, double* longest = nullptr) {
  const Point<3> e01 = p[1] - p[0], e02 = p[2] - p[0], e03 = p[3] - p[0], e12 = p[2] - p[1], e13 = p[3] - p[1],
                 e23 = p[3] - p[2];
  const double l01 = e01.norm(), l02 = e02.norm(), l03 = e03.norm(), l12 = e12.norm(), l13 = e13.norm(),
               l23 = e23.norm();
  if (longest) {
    double hi = 0.0;  // (std::max(hi, NaN) keeps hi, as there)
    for (const double l : {l01, l12, l02, l03, l23, l13}) hi = std::max(hi, l);
    *longest = hi;
  }
  // tet_corner_dets written out (a call there cost the smoothing guard 38 M instructions at
  // sphere966 level 5); lengths |a - c| |b - c| |d - c| per corner.
  const double j[4] = {det3<3>(e01, e02, e03), det3<3>(e12, Point<3>(p[0] - p[1]), e13),
                       det3<3>(Point<3>(p[0] - p[2]), Point<3>(p[1] - p[2]), e23),
                       det3<3>(Point<3>(p[0] - p[3]), Point<3>(p[2] - p[3]), Point<3>(p[1] - p[3]))};
  const double len[4] = {l01 * l02 * l03, l12 * l01 * l13, l02 * l12 * l23, l03 * l23 * l13};
  double m = inf, s = inf;
  for (int k = 0; k < 4; ++k) {
    m = std::min(m, j[k]);
    s = std::min(s, len[k] > 0.0 ? j[k] / len[k] : 0.0);
  }
  return {m, std::clamp(s * normalisation(ElemType::Tet4), -1.0, 1.0)};
}

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define FEBEMESH_TET_LANES 1
// Four tetrahedra a vector, lane by lane the operations of tet_jacobians in its order: Eigen's
// 3-vector cross product (a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0), its dot products and
// squared norms summed left to right ((x0 + x1) + x2), sqrt, no fused multiply-add (the build
// targets no FMA, and this function only AVX), std::min and std::clamp's comparisons as written
// (a NaN lane passes through as there). Plain code, no helpers: a lambda or function taking
// vectors would not inherit the target (-Wpsabi, and no inlining across targets).
[[gnu::target("avx")]] void tet_jacobians_avx(const Point<3>* p, std::size_t n_blocks, double* jac, double* scaled) {
  using V = double __attribute__((vector_size(32)));
  const double root2 = normalisation(ElemType::Tet4);
  for (std::size_t b = 0; b < n_blocks; ++b) {
    const Point<3>* q = p + 16 * b;
    V x[4][3];  // corner, coordinate; lanes = the block's tetrahedra
    for (int c = 0; c < 4; ++c)
      for (int d = 0; d < 3; ++d) x[c][d] = V{q[c][d], q[4 + c][d], q[8 + c][d], q[12 + c][d]};
    // e[i][j] = x[j] - x[i] for the differences tet_jacobians takes.
    V e01[3], e02[3], e03[3], e12[3], e13[3], e23[3], e10[3], e20[3], e21[3], e30[3], e32[3], e31[3];
    for (int d = 0; d < 3; ++d) {
      e01[d] = x[1][d] - x[0][d], e02[d] = x[2][d] - x[0][d], e03[d] = x[3][d] - x[0][d];
      e12[d] = x[2][d] - x[1][d], e13[d] = x[3][d] - x[1][d], e23[d] = x[3][d] - x[2][d];
      e10[d] = x[0][d] - x[1][d], e20[d] = x[0][d] - x[2][d], e21[d] = x[1][d] - x[2][d];
      e30[d] = x[0][d] - x[3][d], e32[d] = x[2][d] - x[3][d], e31[d] = x[1][d] - x[3][d];
    }
#define FEBEMESH_NORM(e) __builtin_ia32_sqrtpd256(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
#define FEBEMESH_DET(a, b, c)                                                                 \
  (a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0]))
    const V l01 = FEBEMESH_NORM(e01), l02 = FEBEMESH_NORM(e02), l03 = FEBEMESH_NORM(e03),
            l12 = FEBEMESH_NORM(e12), l13 = FEBEMESH_NORM(e13), l23 = FEBEMESH_NORM(e23);
    const V j[4] = {FEBEMESH_DET(e01, e02, e03), FEBEMESH_DET(e12, e10, e13), FEBEMESH_DET(e20, e21, e23),
                    FEBEMESH_DET(e30, e32, e31)};
#undef FEBEMESH_NORM
#undef FEBEMESH_DET
    const V len[4] = {l01 * l02 * l03, l12 * l01 * l13, l02 * l12 * l23, l03 * l23 * l13};
    const V zero = V{0, 0, 0, 0};
    V m = V{inf, inf, inf, inf}, s = m;
    for (int k = 0; k < 4; ++k) {
      m = j[k] < m ? j[k] : m;                          // std::min(m, j[k])
      const V r = len[k] > zero ? j[k] / len[k] : zero;  // (a lane of len 0 divides, unused)
      s = r < s ? r : s;
    }
    s = s * root2;
    const V lo = V{-1, -1, -1, -1}, hi = V{1, 1, 1, 1};
    s = s < lo ? lo : (hi < s ? hi : s);  // std::clamp
    for (int k = 0; k < 4; ++k) jac[4 * b + k] = m[k], scaled[4 * b + k] = s[k];
  }
}
#endif

}  // namespace

void tet_jacobians_n(const Point<3>* p, std::size_t n, double* jac, double* scaled) {
  std::size_t done = 0;
#ifdef FEBEMESH_TET_LANES
  static const bool avx = __builtin_cpu_supports("avx");
  if (avx) {
    tet_jacobians_avx(p, n / 4, jac, scaled);
    done = n / 4 * 4;
  }
#endif
  for (std::size_t t = done; t < n; ++t) std::tie(jac[t], scaled[t]) = tet_jacobians(std::span<const Point<3>>(p + 4 * t, 4));
}

template <int Dim> double min_corner_jacobian(ElemType t, std::span<const Point<Dim>> p) {
  MESH_ASSERT(static_cast<int>(p.size()) == n_nodes(t), name(t) << " with " << p.size() << " points");
  if (t == ElemType::Line2) return (p[1] - p[0]).norm();
  if constexpr (Dim == 3) {
    if (t == ElemType::Tet4) {  // the validator's orientation check: the same numbers, no tables
      double m = inf;  // (from inf as below: a NaN corner is passed over the same way)
      for (const double j : tet_corner_dets(p)) m = std::min(m, j);
      return m;
    }
  }
  double m = inf;
  for (const Corner& k : corners(t)) m = std::min(m, corner_jacobian<Dim>(t, k, p).first);
  return m;
}

template <int Dim> double scaled_jacobian(ElemType t, std::span<const Point<Dim>> p) {
  if constexpr (Dim == 2) {
    if (t == ElemType::Tri3) return polygon_jacobians<3>(p.data(), normalisation(t)).second;
    if (t == ElemType::Quad4) return polygon_jacobians<4>(p.data(), normalisation(t)).second;
  }
  if constexpr (Dim == 3) {
    if (t == ElemType::Tet4) return tet_jacobians(p).second;  // the same numbers, 6 norms, not 12
  }
  if (t == ElemType::Line2) return (p[1] - p[0]).norm() > 0.0 ? 1.0 : 0.0;
  double m = inf;
  for (const Corner& k : corners(t)) {
    const auto [jac, lengths] = corner_jacobian<Dim>(t, k, p);
    m = std::min(m, lengths > 0.0 ? jac / lengths : 0.0);
  }
  return std::clamp(m * normalisation(t), -1.0, 1.0);
}

template <int Dim> std::pair<double, double> jacobians(ElemType t, std::span<const Point<Dim>> p) {
  if constexpr (Dim == 2) {
    if (t == ElemType::Tri3) return polygon_jacobians<3>(p.data(), normalisation(t));
    if (t == ElemType::Quad4) return polygon_jacobians<4>(p.data(), normalisation(t));
  }
  if (t == ElemType::Line2) return {min_corner_jacobian<Dim>(t, p), scaled_jacobian<Dim>(t, p)};
  if constexpr (Dim == 3) {
    if (t == ElemType::Tet4) return tet_jacobians(p);
  }
  double m = inf, s = inf;
  for (const Corner& k : corners(t)) {
    const auto [jac, lengths] = corner_jacobian<Dim>(t, k, p);
    m = std::min(m, jac);
    s = std::min(s, lengths > 0.0 ? jac / lengths : 0.0);
  }
  return {m, std::clamp(s * normalisation(t), -1.0, 1.0)};
}

template <int Dim> double signed_measure(ElemType t, std::span<const Point<Dim>> p) {
  switch (t) {
    case ElemType::Line2: return (p[1] - p[0]).norm();
    case ElemType::Tri3: return 0.5 * cross2<Dim>(p[1] - p[0], p[2] - p[0]);
    case ElemType::Quad4:
      // Diagonals' cross product: exact for a planar quad, also non-convex ones.
      return 0.5 * cross2<Dim>(p[2] - p[0], p[3] - p[1]);
    case ElemType::Tet4: return tet_signed_measure<Dim>(p);
    default: break;
  }
  if constexpr (Dim == 3) {
    // Divergence theorem over the (triangulated) faces, relative to the first node. A quad face
    // counts as the mean of its two diagonal splits: a non-planar quad shared by two elements
    // (hex-dominant meshes) then cancels exactly, as it does in interface_enclosed_measure.
    double v = 0.0;
    for (int f = 0; f < n_facets(t); ++f) {
      const auto local = facet_local_nodes(t, f);
      const auto fan = [&](std::size_t s) {
        double w = 0.0;
        for (std::size_t i = 1; i + 1 < local.size(); ++i) {
          const Point<3> a = p[local[s]] - p[0], b = p[local[(s + i) % local.size()]] - p[0],
                         c = p[local[(s + i + 1) % local.size()]] - p[0];
          w += a.dot(b.cross(c));
        }
        return w;
      };
      v += local.size() == 4 ? 0.5 * (fan(0) + fan(1)) : fan(0);
    }
    return v / 6.0;
  } else {
    MESH_ASSERT(false, "3D element in a 2D mesh");
    return 0.0;
  }
}

namespace {

/// element_quality's aspect ratio of a polygon (Verdict's, 1 = ideal).
template <int Dim> double polygon_aspect_ratio(ElemType t, std::span<const Point<Dim>> p) {
  double sum = 0.0;
  const double longest = edge_length_range<Dim>(t, p, &sum).second;
  const double area = std::abs(signed_measure<Dim>(t, p));
  const double denom = (t == ElemType::Tri3 ? 4.0 * std::sqrt(3.0) : 4.0) * area;
  return denom > 0.0 ? longest * sum / denom : inf;
}

}  // namespace

template <int Dim> ElementQuality element_quality(ElemType t, std::span<const Point<Dim>> p) {
  ElementQuality q;
  q.scaled_jacobian = scaled_jacobian<Dim>(t, p);
  if (t == ElemType::Line2) {
    q.min_angle_deg = q.max_angle_deg = 180.0;
    q.aspect_ratio = 1.0;
    return q;
  }
  if (dimension(t) == 2) {
    q.min_angle_deg = inf;
    q.max_angle_deg = -inf;
    double key[8];
    const int n = polygon_corner_keys<Dim>(t, p, key);
    for (int i = 0; i < n; ++i) {
      const double a = angle_of_key(key[i]);
      q.min_angle_deg = std::min(q.min_angle_deg, a);
      q.max_angle_deg = std::max(q.max_angle_deg, a);
    }
    q.aspect_ratio = polygon_aspect_ratio<Dim>(t, p);
    return q;
  }
  if constexpr (Dim == 3) {
    std::tie(q.min_angle_deg, q.max_angle_deg) = dihedral_range(t, p);
    if (t == ElemType::Tet4) {
      const double longest = edge_length_range<3>(t, p).second;
      double area = 0.0;
      for (int f = 0; f < 4; ++f) area += facet_normal(t, f, p).norm();
      const double volume = std::abs(signed_measure<3>(t, p));
      q.aspect_ratio = volume > 0.0 ? longest * area / (6.0 * std::sqrt(6.0) * volume) : inf;
      q.radius_ratio = tet_radius_ratio<3>(p);
    } else {
      const auto [shortest, longest] = edge_length_range<3>(t, p);
      q.aspect_ratio = shortest > 0.0 ? longest / shortest : inf;
    }
  }
  return q;
}

template <int Dim> ElemPoints<Dim> element_points(const Elements& els, ElemId e, const std::vector<Point<Dim>>& pts) {
  ElemPoints<Dim> out;
  out.n = els.n_nodes_of(e);
  const VertexId* nodes = els.nodes(e);
  for (int i = 0; i < out.n; ++i) out.p[i] = pts[nodes[i].v];
  return out;
}

template <int Dim> std::vector<double> scaled_jacobians(const Elements& els, const std::vector<Point<Dim>>& pts) {
  std::vector<double> out(els.size());
  for (std::size_t e = 0; e < els.size(); ++e) {
    const auto ep = element_points<Dim>(els, ElemId{static_cast<std::int32_t>(e)}, pts);
    out[e] = scaled_jacobian<Dim>(els.type[e], ep.span());
  }
  return out;
}

namespace {

// summarize_quality's tetrahedra (issue 8: the summary was 11% of sphere966 level 5): every
// number of element_quality and signed_measure as they compute it, with each facet normal, edge
// length and the measure computed once, and the dihedral angles kept as their keys (the cosine
// between the facets' outward normals, 1 for a degenerate facet): the angle is 180 - acos(key)
// in degrees, non-decreasing in the key, so acos is taken only where an extreme or the sliver
// test needs it. Keys farther apart than key_gap give acos results in the same order (|acos'| >= 1,
// and acos is within an ulp), so only the keys within key_gap of an extreme can give that extreme.
constexpr double key_gap = 1e-9;

double dihedral_of_key(double key) { return 180.0 - std::acos(key) * rad_to_deg; }

struct TetTerms {
  double scaled_jacobian, aspect_ratio, radius_ratio, measure;
  std::array<double, 6> key;  ///< per edge, in edge_local_nodes order; NaN ones are ignored
  double key_lo, key_hi;      ///< extremes of the non-NaN keys (inf, -inf without any)
};

/// The two facets of each edge of a tetrahedron, as dihedral_range finds them.
const std::array<std::array<int, 2>, 6>& tet_edge_facets() {
  static const auto table = [] {
    std::array<std::array<int, 2>, 6> out{};
    constexpr ElemType t = ElemType::Tet4;
    for (int e = 0; e < n_edges(t); ++e) {
      const auto [a, b] = edge_local_nodes(t, e);
      int found = 0;
      for (int f = 0; f < n_facets(t) && found < 2; ++f)
        if (facet_has_edge(facet_local_nodes(t, f), a, b)) out[e][found++] = f;
      MESH_ASSERT(found == 2, "edge " << e);
    }
    return out;
  }();
  return table;
}

TetTerms tet_terms(std::span<const Point<3>> p) {
  constexpr ElemType t = ElemType::Tet4;
  TetTerms r;
  double longest = 0.0;  // edge_length_range's maximum, from the edge lengths tet_jacobians takes
  r.scaled_jacobian = tet_jacobians(p, &longest).second;
  Point<3> normal[4];
  double normal_len[4];
  double area = 0.0;
  for (int f = 0; f < 4; ++f) {
    normal[f] = tet_facet_normal(f, p);
    normal_len[f] = normal[f].norm();
    area += normal_len[f];
  }
  r.measure = signed_measure<3>(t, p);
  const double volume = std::abs(r.measure);
  r.aspect_ratio = volume > 0.0 ? longest * area / (6.0 * std::sqrt(6.0) * volume) : inf;
  {  // tet_radius_ratio, with its facet area sum shared
    const Point<3> a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const double det = a.dot(b.cross(c));
    if (det <= 0.0) {
      r.radius_ratio = inf;
    } else {
      const Point<3> num = a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b);
      const double circum = num.norm() / (2.0 * det);
      const double in = det / (2.0 * area);
      r.radius_ratio = circum / (3.0 * in);
    }
  }
  // angle_deg's cosine, clamped; a zero normal gives 0 degrees there, acos(1) here.
  const auto& pairs = tet_edge_facets();
  r.key_lo = inf;
  r.key_hi = -inf;
  for (int e = 0; e < 6; ++e) {
    const int f0 = pairs[e][0], f1 = pairs[e][1];
    const double na = normal_len[f0], nb = normal_len[f1];
    const double k = na == 0.0 || nb == 0.0 ? 1.0 : std::clamp(normal[f0].dot(normal[f1]) / (na * nb), -1.0, 1.0);
    r.key[e] = k;
    if (k < r.key_lo) r.key_lo = k;
    if (k > r.key_hi) r.key_hi = k;
  }
  return r;
}

/// A chunk's smallest and largest angle and its sliver count from its elements' angle keys,
/// angle_of(key) non-decreasing in the key (the tetrahedra's dihedral keys; the polygons' corner
/// cosines negated): an element's extreme angle comes from the keys within key_gap of its extreme
/// key, and an element whose extreme key is farther than key_gap beyond the chunk's running one
/// cannot hold the chunk's extreme, so acos is taken only there and near the sliver threshold.
/// NaN keys are passed over.
template <class AngleOf> class KeyedAngles {
 public:
  /// Slivers: elements whose smallest angle is under threshold_deg; key_sliver is the key of
  /// that angle (used when by_key: 0 < threshold < 180).
  KeyedAngles(AngleOf angle_of, double threshold_deg, double key_sliver)
      : angle_of_(angle_of), threshold_(threshold_deg), by_key_(threshold_deg > 0.0 && threshold_deg < 180.0),
        key_sliver_(key_sliver) {}

  /// An element's n keys, key_lo and key_hi their extremes over the non-NaN ones (inf, -inf
  /// without any): its terms of p's smallest and largest angle and of its sliver count.
  void add(const double* key, int n, double key_lo, double key_hi, QualitySummary& p) {
    double lo = std::numeric_limits<double>::quiet_NaN();  // NaN: not computed
    if (key_lo <= run_lo_ + key_gap) {
      lo = smallest(key, n, key_lo);
      p.min_angle_deg = std::min(p.min_angle_deg, lo);
      run_lo_ = std::min(run_lo_, key_lo);
    }
    if (key_hi >= run_hi_ - key_gap) {
      double hi = -inf;
      for (int i = 0; i < n; ++i)
        if (key[i] >= key_hi - key_gap) hi = std::max(hi, angle_of_(key[i]));
      p.max_angle_deg = std::max(p.max_angle_deg, hi);
      run_hi_ = std::max(run_hi_, key_hi);
    }
    // Below key_sliver - 1e-7 the smallest angle is surely under the threshold, above
    // key_sliver + 1e-7 surely not (1e-7 rad is far above acos's error); in between it is computed.
    bool sliver;
    if (by_key_ && key_lo < key_sliver_ - 1e-7) {
      sliver = true;
    } else if (by_key_ && key_lo > key_sliver_ + 1e-7) {
      sliver = false;
    } else {
      if (std::isnan(lo)) lo = smallest(key, n, key_lo);
      sliver = lo < threshold_;
    }
    if (sliver) ++p.n_slivers;
  }

 private:
  double smallest(const double* key, int n, double key_lo) const {
    double lo = inf;
    for (int i = 0; i < n; ++i)
      if (key[i] <= key_lo + key_gap) lo = std::min(lo, angle_of_(key[i]));
    return lo;
  }

  AngleOf angle_of_;
  double threshold_;
  bool by_key_;
  double key_sliver_;
  double run_lo_ = inf, run_hi_ = -inf;  ///< the chunk's running extreme keys
};

/// Summary terms of tetrahedra [begin, end) into p and sum_sj, as the generic loop adds them.
template <int Dim>
void summarize_tets(const Mesh<Dim>& mesh, std::size_t begin, std::size_t end, double sliver_threshold_deg,
                    QualitySummary& p, double& sum_sj) {
  if constexpr (Dim == 3) {
    const double th = sliver_threshold_deg;
    KeyedAngles angles(dihedral_of_key, th, th > 0.0 && th < 180.0 ? std::cos((180.0 - th) / rad_to_deg) : 0.0);
    for (std::size_t e = begin; e < end; ++e) {
      const auto ep = element_points<3>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
      const TetTerms r = tet_terms(ep.span());
      p.min_scaled_jacobian = std::min(p.min_scaled_jacobian, r.scaled_jacobian);
      sum_sj += r.scaled_jacobian;
      angles.add(r.key.data(), 6, r.key_lo, r.key_hi, p);
      p.max_aspect_ratio = std::max(p.max_aspect_ratio, r.aspect_ratio);
      p.max_radius_ratio = std::max(p.max_radius_ratio, r.radius_ratio);
      const int bin = std::clamp(static_cast<int>(std::floor((r.scaled_jacobian + 1.0) / 0.2)), 0, 9);
      ++p.scaled_jacobian_histogram[bin];
      p.measure += r.measure;
    }
  } else {
    (void)mesh, (void)begin, (void)end, (void)sliver_threshold_deg, (void)p, (void)sum_sj;
    MESH_ASSERT(false, "tetrahedra in a 2D mesh");
  }
}

/// One element's terms into p and sum_sj (its quality q and signed measure), the generic way.
void add_element(const ElementQuality& q, double measure, double sliver_threshold_deg, QualitySummary& p, double& sum_sj) {
  p.min_scaled_jacobian = std::min(p.min_scaled_jacobian, q.scaled_jacobian);
  sum_sj += q.scaled_jacobian;
  p.min_angle_deg = std::min(p.min_angle_deg, q.min_angle_deg);
  p.max_angle_deg = std::max(p.max_angle_deg, q.max_angle_deg);
  p.max_aspect_ratio = std::max(p.max_aspect_ratio, q.aspect_ratio);
  p.max_radius_ratio = std::max(p.max_radius_ratio, q.radius_ratio);
  const int bin = std::clamp(static_cast<int>(std::floor((q.scaled_jacobian + 1.0) / 0.2)), 0, 9);
  ++p.scaled_jacobian_histogram[bin];
  if (q.min_angle_deg < sliver_threshold_deg) ++p.n_slivers;
  p.measure += measure;
}

// summarize_quality's triangles and quads: every number of element_quality and signed_measure
// as they compute it, with each edge vector and length computed once (a corner's two edges are
// e[c] and -e[c - 1]: a vector and its negation have the same norm and products, bit for bit),
// and the corner angles kept as keys for KeyedAngles, as for the tetrahedra above: the cosines
// polygon_corner_keys takes, negated (the angle, angle_of_key(-key), rises with the key; a
// negation is exact, and so are the comparisons of negated numbers).
template <int n> struct PolygonTerms {
  double key[n];          ///< -cos of each corner angle, in corners(t)'s order
  double key_lo, key_hi;  ///< extremes of the keys
  double scaled_jacobian, aspect_ratio, measure;
};
template <int n> PolygonTerms<n> polygon_terms(ElemType t, std::span<const Point<2>> p) {
  PolygonTerms<n> r;
  Point<2> e[n];
  double len[n];
  double sum = 0.0, longest = 0.0;  // edge_length_range's, edge i = (i, i + 1)
  for (int i = 0; i < n; ++i) {
    e[i] = p[(i + 1) % n] - p[i];
    len[i] = e[i].norm();
    longest = std::max(longest, len[i]);
    sum += len[i];
  }
  r.key_lo = inf, r.key_hi = -inf;
  for (int c = 0; c < n; ++c) {  // corners(t): corner c between p[c + 1] and p[c - 1]
    const int prev = (c + n - 1) % n;
    const double na = len[c], nb = len[prev];
    const double k = -(na == 0.0 || nb == 0.0 ? 1.0 : std::clamp(e[c].dot(-e[prev]) / (na * nb), -1.0, 1.0));
    r.key[c] = k;
    r.key_lo = std::min(r.key_lo, k), r.key_hi = std::max(r.key_hi, k);
  }
  r.scaled_jacobian = polygon_jacobians<n>(p.data(), normalisation(t)).second;
  r.measure = signed_measure<2>(t, p);
  const double denom = (n == 3 ? 4.0 * std::sqrt(3.0) : 4.0) * std::abs(r.measure);  // polygon_aspect_ratio
  r.aspect_ratio = denom > 0.0 ? longest * sum / denom : inf;
  return r;
}

/// Summary terms of the triangles and quads [begin, end) of a 2D mesh into p and sum_sj, as
/// the generic loop adds them (an element with a key that is not finite goes that way).
template <int Dim>
void summarize_polygons(const Mesh<Dim>& mesh, std::size_t begin, std::size_t end, double sliver_threshold_deg,
                        QualitySummary& p, double& sum_sj) {
  if constexpr (Dim == 2) {
    const double th = sliver_threshold_deg;
    KeyedAngles angles([](double key) { return angle_of_key(-key); }, th,
                       th > 0.0 && th < 180.0 ? -std::cos(th / rad_to_deg) : 0.0);
    const auto add = [&](ElemType t, std::span<const Point<2>> ep, const auto& r) {
      if (!std::all_of(std::begin(r.key), std::end(r.key), [](double k) { return std::isfinite(k); })) {
        add_element(element_quality<2>(t, ep), signed_measure<2>(t, ep), th, p, sum_sj);
        return;
      }
      p.min_scaled_jacobian = std::min(p.min_scaled_jacobian, r.scaled_jacobian);
      sum_sj += r.scaled_jacobian;
      angles.add(r.key, static_cast<int>(std::size(r.key)), r.key_lo, r.key_hi, p);
      p.max_aspect_ratio = std::max(p.max_aspect_ratio, r.aspect_ratio);
      p.max_radius_ratio = std::max(p.max_radius_ratio, ElementQuality{}.radius_ratio);
      const int bin = std::clamp(static_cast<int>(std::floor((r.scaled_jacobian + 1.0) / 0.2)), 0, 9);
      ++p.scaled_jacobian_histogram[bin];
      p.measure += r.measure;
    };
    for (std::size_t e = begin; e < end; ++e) {
      const ElemType t = mesh.solid.type[e];
      const auto ep = element_points<2>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
      if (t == ElemType::Tri3) add(t, ep.span(), polygon_terms<3>(t, ep.span()));
      else add(t, ep.span(), polygon_terms<4>(t, ep.span()));
    }
  } else {
    (void)mesh, (void)begin, (void)end, (void)sliver_threshold_deg, (void)p, (void)sum_sj;
    MESH_ASSERT(false, "polygons in a 3D mesh's solid");
  }
}

}  // namespace

template <int Dim>
QualitySummary summarize_quality(const Mesh<Dim>& mesh, double sliver_threshold_deg, int n_threads) {
  QualitySummary s;
  s.sliver_threshold_deg = sliver_threshold_deg;
  s.n_elements = mesh.solid.size();
  if (s.n_elements == 0) return s;
  // Partial summaries of fixed chunks, combined in chunk order: the sums (mean scaled Jacobian,
  // measure) round the same way for every thread count.
  constexpr std::size_t chunk = 1 << 14;
  struct Part {
    QualitySummary s;
    double sum_sj = 0.0;
  };
  std::vector<Part> parts((s.n_elements + chunk - 1) / chunk);
  for_each_chunk(s.n_elements, chunk, n_threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
    QualitySummary& p = parts[c].s;
    p.min_scaled_jacobian = inf;
    p.min_angle_deg = inf;
    p.max_angle_deg = -inf;
    if constexpr (Dim == 3) {
      const bool all_tets = std::all_of(mesh.solid.type.begin() + begin, mesh.solid.type.begin() + end,
                                        [](ElemType t) { return t == ElemType::Tet4; });
      if (all_tets) {
        summarize_tets<Dim>(mesh, begin, end, sliver_threshold_deg, p, parts[c].sum_sj);
        return;
      }
    }
    if constexpr (Dim == 2) {
      const bool all_polygons = std::all_of(mesh.solid.type.begin() + begin, mesh.solid.type.begin() + end,
                                            [](ElemType t) { return t == ElemType::Tri3 || t == ElemType::Quad4; });
      if (all_polygons) {
        summarize_polygons<Dim>(mesh, begin, end, sliver_threshold_deg, p, parts[c].sum_sj);
        return;
      }
    }
    for (std::size_t e = begin; e < end; ++e) {
      const ElemType t = mesh.solid.type[e];
      const auto ep = element_points<Dim>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
      add_element(element_quality<Dim>(t, ep.span()), signed_measure<Dim>(t, ep.span()), sliver_threshold_deg, p, parts[c].sum_sj);
    }
  });
  s.min_scaled_jacobian = inf;
  s.min_angle_deg = inf;
  s.max_angle_deg = -inf;
  double sum_sj = 0.0;
  for (const Part& part : parts) {
    const QualitySummary& p = part.s;
    s.min_scaled_jacobian = std::min(s.min_scaled_jacobian, p.min_scaled_jacobian);
    sum_sj += part.sum_sj;
    s.min_angle_deg = std::min(s.min_angle_deg, p.min_angle_deg);
    s.max_angle_deg = std::max(s.max_angle_deg, p.max_angle_deg);
    s.max_aspect_ratio = std::max(s.max_aspect_ratio, p.max_aspect_ratio);
    s.max_radius_ratio = std::max(s.max_radius_ratio, p.max_radius_ratio);
    for (std::size_t b = 0; b < s.scaled_jacobian_histogram.size(); ++b)
      s.scaled_jacobian_histogram[b] += p.scaled_jacobian_histogram[b];
    s.n_slivers += p.n_slivers;
    s.measure += p.measure;
  }
  s.mean_scaled_jacobian = sum_sj / static_cast<double>(s.n_elements);
  return s;
}

template <int Dim> double solid_measure(const Mesh<Dim>& mesh, int n_threads) {
  // The elements' measures a block at a time on n_threads threads, summed in element order on
  // one: the serial sum, bit for bit, for every count (serial, it was 0.08 s of sphere966 L6's
  // 2.9 s on two threads), and 2 MB beside the mesh.
  constexpr std::size_t block = std::size_t(1) << 18;
  std::vector<double> part(std::min(block, mesh.solid.size()));
  double m = 0.0;
  for (std::size_t first = 0; first < mesh.solid.size(); first += block) {
    const std::size_t n_here = std::min(block, mesh.solid.size() - first);
    for_each_range(n_here, n_threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const std::size_t e = first + i;
        const auto ep = element_points<Dim>(mesh.solid, ElemId{static_cast<std::int32_t>(e)}, mesh.points);
        part[i] = signed_measure<Dim>(mesh.solid.type[e], ep.span());
      }
    });
    for (std::size_t i = 0; i < n_here; ++i) m += part[i];
  }
  return m;
}

template <int Dim> double interface_enclosed_measure(const Mesh<Dim>& mesh) {
  if (mesh.interface.empty()) return 0.0;
  // Relative to the box centre: keeps the cancellation error small far from the origin.
  Box<Dim> box = Box<Dim>::empty();
  for (const VertexId v : mesh.interface.node) box.expand(mesh.points[v.v]);
  const Point<Dim> o = box.center();
  double m = 0.0;
  for (std::size_t e = 0; e < mesh.interface.size(); ++e) {
    const VertexId* n = mesh.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    const int k = mesh.interface.n_nodes_of(ElemId{static_cast<std::int32_t>(e)});
    if constexpr (Dim == 2) {
      const Point<2> a = mesh.points[n[0].v] - o, b = mesh.points[n[1].v] - o;
      m += 0.5 * (a.x() * b.y() - a.y() * b.x());
    } else {
      // A quad as the mean of its two diagonal splits (as signed_measure counts element faces).
      const int n_fans = k == 4 ? 2 : 1;
      for (int s = 0; s < n_fans; ++s) {
        const Point<3> a = mesh.points[n[s].v] - o;
        for (int i = 1; i + 1 < k; ++i) {
          const Point<3> b = mesh.points[n[(s + i) % k].v] - o, c = mesh.points[n[(s + i + 1) % k].v] - o;
          m += a.dot(b.cross(c)) / (6.0 * n_fans);
        }
      }
    }
  }
  return m;
}

#define FEBEMESH_INSTANTIATE(D)                                                                     \
  template double min_corner_jacobian<D>(ElemType, std::span<const Point<D>>);                     \
  template double scaled_jacobian<D>(ElemType, std::span<const Point<D>>);                         \
  template std::pair<double, double> jacobians<D>(ElemType, std::span<const Point<D>>);           \
  template double signed_measure<D>(ElemType, std::span<const Point<D>>);                          \
  template ElementQuality element_quality<D>(ElemType, std::span<const Point<D>>);                 \
  template ElemPoints<D> element_points<D>(const Elements&, ElemId, const std::vector<Point<D>>&); \
  template std::vector<double> scaled_jacobians<D>(const Elements&, const std::vector<Point<D>>&); \
  template QualitySummary summarize_quality<D>(const Mesh<D>&, double, int);                       \
  template double solid_measure<D>(const Mesh<D>&, int);                                           \
  template double interface_enclosed_measure<D>(const Mesh<D>&);
FEBEMESH_INSTANTIATE(2)
FEBEMESH_INSTANTIATE(3)
#undef FEBEMESH_INSTANTIATE

}  // namespace febemesh
