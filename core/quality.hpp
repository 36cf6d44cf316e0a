#pragma once
// Element quality with the Verdict definitions (Knupp, "The Verdict Geometric Quality Library",
// SAND2007-1751) and mesh summaries; dimension-generic, instantiated for Dim = 2 and 3.
// Points are given in the ambient dimension Dim: a triangle in 3D (an interface element) is
// measured unsigned, a full-dimensional element signed (positive = counter-clockwise / positive
// volume with Gmsh's node order).

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "core/mesh.hpp"

namespace febemesh {

struct ElementQuality {
  double scaled_jacobian = 0.0;  ///< min over corners, normalised so the ideal shape is 1; <= 0 inverted
  double min_angle_deg = 0.0;    ///< 2D elements: interior (corner) angles; 3D elements: dihedral angles
  double max_angle_deg = 0.0;
  double aspect_ratio = 0.0;     ///< Verdict for tri, quad, tet (1 = ideal); else longest / shortest edge
  double radius_ratio = 0.0;     ///< tets: Verdict R / (3 r), 1 = regular; 0 for other types
};

/// Smallest corner Jacobian (2D: cross product of the two corner edges; 3D: determinant of the
/// three corner edges; Gmsh order, pyramid: the four base corners). > 0 for a valid element.
template <int Dim> double min_corner_jacobian(ElemType t, std::span<const Point<Dim>> p);
/// Verdict scaled Jacobian: min over corners of J / (product of corner edge lengths), times
/// 2/sqrt(3) (tri, prism), sqrt(2) (tet, pyramid), 1 (quad, hex); clamped to [-1, 1].
template <int Dim> double scaled_jacobian(ElemType t, std::span<const Point<Dim>> p);
/// Both at once, {min_corner_jacobian, scaled_jacobian} (the same values; one pass over the
/// corners, for the smoothing guard that needs both per trial move).
template <int Dim> std::pair<double, double> jacobians(ElemType t, std::span<const Point<Dim>> p);
/// jacobians(Tet4, ...) of n tetrahedra, those of tetrahedron i at p[4 i .. 4 i + 3]:
/// {jac[i], scaled[i]}, the same numbers bit for bit, four tetrahedra at a time in AVX registers
/// where the CPU has them (the 3D smoothing guard, which ranks all of a node's tetrahedra).
void tet_jacobians_n(const Point<3>* p, std::size_t n, double* jac, double* scaled);
/// jacobians() of a triangle (n = 3) or quadrilateral (n = 4) in the plane, with `normalise`
/// 2/sqrt(3) or 1: corner i spans edges e[i] = p[i+1] - p[i] and -e[i-1], so each edge length is
/// taken once and reused (a vector and its negation have the same norm, bit for bit); the same
/// numbers as the corner loop. Inline for the 2D smoothing guard, its hot path.
template <int n> std::pair<double, double> polygon_jacobians(const Point<2>* p, double normalise) {
  static_assert(n == 3 || n == 4);
  Point<2> e[n];
  double len[n];
  for (int i = 0; i < n; ++i) {
    e[i] = p[(i + 1) % n] - p[i];
    len[i] = e[i].norm();
  }
  double m = std::numeric_limits<double>::infinity(), s = m;
  for (int i = 0; i < n; ++i) {
    const int prev = (i + n - 1) % n;
    const Point<2> a = e[i], b = -e[prev];
    const double jac = a.x() * b.y() - a.y() * b.x(), lengths = len[i] * len[prev];
    m = std::min(m, jac);
    s = std::min(s, lengths > 0.0 ? jac / lengths : 0.0);
  }
  return {m, std::clamp(s * normalise, -1.0, 1.0)};
}
/// Signed length / area / volume (unsigned for an element of lower dimension than Dim).
template <int Dim> double signed_measure(ElemType t, std::span<const Point<Dim>> p);
template <int Dim> ElementQuality element_quality(ElemType t, std::span<const Point<Dim>> p);

/// Node coordinates of element e (at most 8).
template <int Dim> struct ElemPoints {
  std::array<Point<Dim>, 8> p;
  int n = 0;
  std::span<const Point<Dim>> span() const { return {p.data(), static_cast<std::size_t>(n)}; }
};
template <int Dim> ElemPoints<Dim> element_points(const Elements& els, ElemId e, const std::vector<Point<Dim>>& pts);

/// Scaled Jacobian of every element of `els` (the "quality" cell field of the VTU writer).
template <int Dim> std::vector<double> scaled_jacobians(const Elements& els, const std::vector<Point<Dim>>& pts);

struct QualitySummary {
  std::size_t n_elements = 0;
  double min_scaled_jacobian = 0.0;
  double mean_scaled_jacobian = 0.0;
  double min_angle_deg = 0.0;  ///< 2D: over triangle and quad corners; 3D: dihedral angles
  double max_angle_deg = 0.0;
  double max_aspect_ratio = 0.0;
  double max_radius_ratio = 0.0;  ///< tets only; 0 without tets
  /// Scaled Jacobian counts in 10 bins of width 0.2 on [-1, 1] (bin 9 includes 1).
  std::array<std::size_t, 10> scaled_jacobian_histogram{};
  double sliver_threshold_deg = 0.0;
  std::size_t n_slivers = 0;  ///< elements whose min angle (3D: min dihedral) is below the threshold
  double measure = 0.0;       ///< area (2D) / volume (3D) of the solid
};

/// Summary over the solid elements. Sliver threshold: 10 degrees by default. On n_threads
/// threads, with the same result (bit for bit) for every thread count.
template <int Dim>
QualitySummary summarize_quality(const Mesh<Dim>& mesh, double sliver_threshold_deg = 10.0, int n_threads = 1);

/// Area (2D) / volume (3D) of the solid elements, signed; summed in element order, the elements'
/// measures taken on n_threads threads (the same sum for every count).
template <int Dim> double solid_measure(const Mesh<Dim>& mesh, int n_threads = 1);
/// Area of the polygons (2D) / volume of the surface (3D) bounded by the interface elements,
/// by the divergence theorem; equals solid_measure when the interface is the outward boundary.
template <int Dim> double interface_enclosed_measure(const Mesh<Dim>& mesh);

}  // namespace febemesh
