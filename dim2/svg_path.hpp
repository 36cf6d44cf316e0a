#pragma once
// SVG's attribute mini-languages that carry geometry: path data (`d`: M L H V C S Q T A Z,
// absolute and relative, implicit repeats) and `transform` lists; and the exact conversion of
// path segments to the cubic Bezier pieces of the curve model (DESIGN.md: Beziers become the
// composite B-spline form exactly; only elliptical arcs are approximated, to a stated bound).

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

/// Largest coordinate magnitude accepted from a file: beyond it, squared distances and areas lose
/// all precision (and 4^level cells could not resolve the drawing anyway).
inline constexpr double max_coordinate = 1e15;

/// Broken path data or transform: `offset` is the byte in the attribute value where it went wrong.
class PathDataError : public std::runtime_error {
 public:
  PathDataError(std::size_t offset, const std::string& why) : std::runtime_error(why), offset_(offset) {}
  std::size_t offset() const { return offset_; }

 private:
  std::size_t offset_;
};

/// x -> a x + b: SVG's matrix(a b c d e f) is a = [[a c] [b d]], b = (e, f).
struct Affine {
  Eigen::Matrix2d a = Eigen::Matrix2d::Identity();
  P2 b = P2::Zero();

  P2 operator()(const P2& p) const { return a * p + b; }
  /// (*this)(other(p)): `other` is applied first.
  Affine operator*(const Affine& other) const { return Affine{a * other.a, a * other.b + b}; }
  /// Largest stretch factor (spectral norm of a): bounds how errors grow under the map.
  double stretch() const;
};

/// Parses an SVG transform list ("translate(1 2) rotate(30)"); the result applies the rightmost
/// transform first, as SVG does. Empty or blank text gives the identity.
Affine parse_transform(std::string_view text);

struct PathSegment {
  enum class Kind : std::uint8_t { Line, Quadratic, Cubic, Arc };
  Kind kind = Kind::Line;
  /// Line: p[0], p[3]. Quadratic: p[0], p[1] (control), p[3]. Cubic: all. Arc: p[0], p[3].
  std::array<P2, 4> p{P2::Zero(), P2::Zero(), P2::Zero(), P2::Zero()};
  double rx = 0.0, ry = 0.0, rotation_deg = 0.0;  ///< arc radii and x-axis rotation
  bool large_arc = false, sweep = false;          ///< arc flags
  std::size_t offset = 0;                         ///< of the command in the path data
};

struct Subpath {
  std::vector<PathSegment> segments;
  bool closed = false;     ///< ended with Z
  std::size_t offset = 0;  ///< of its moveto
};

/// Parses path data into subpaths in absolute user coordinates. Follows the SVG 1.1 grammar
/// strictly (unlike browsers, which render up to the first error): an error anywhere refuses the
/// whole path, because a partly read outline is a different solid. Rejects non-finite numbers and
/// magnitudes above max_coordinate.
std::vector<Subpath> parse_path_data(std::string_view d);

/// A straight cubic: control points at 1/3 and 2/3, so the parameterisation is uniform.
Bezier straight_cubic(const P2& a, const P2& b);

/// Exact degree elevation of the quadratic (a, c, b).
Bezier elevate_quadratic(const P2& a, const P2& c, const P2& b);

/// Upper bound of the radial error of the standard cubic approximation (handle length
/// 4/3 tan(sweep/4)) of a unit circular arc of angle `sweep` (Goldapp 1991; the true maximum is
/// half of it, the factor 2 is margin).
double arc_radial_error_bound(double sweep);

/// Appends the cubic pieces of segment `s` mapped by `m`. Lines, quadratics and cubics are exact;
/// an arc is split into equal sweeps until its radial error after `m` is below `tolerance`.
/// Degenerate pieces (all control points equal) are skipped. Throws PathDataError when an arc
/// would need an absurd number of pieces (tolerance far below the radius' precision).
void append_beziers(const PathSegment& s, const Affine& m, double tolerance, std::vector<Bezier>& out);

/// Signed area enclosed by closed consecutive pieces (Green's theorem, exact for cubics:
/// the integrand x y' - y x' has degree 5, integrated by 3-point Gauss-Legendre).
double signed_area(const std::vector<Bezier>& pieces);

}  // namespace febemesh::dim2
