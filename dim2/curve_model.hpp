#pragma once
// The paper's geometric model: closed composite non-uniform cubic B-spline loops. Internally a
// loop is stored in its exact piecewise Bezier form (one cubic Bezier per knot span, obtained by
// knot insertion), which makes evaluation, bounding boxes and closest points simple and exact.
// Junctions between pieces are corners (C0 with a tangent jump: the paper's tripled knot) or
// smooth.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/box.hpp"

namespace febemesh::dim2 {

using P2 = Point<2>;
using Bezier = std::array<P2, 4>;

inline constexpr double no_level = -1.0;  ///< "no mesh control parameter here"

/// A control point of the native B-spline input (paper: simple or corner, with an optional level).
struct ControlPoint {
  P2 p = P2::Zero();
  bool corner = false;     ///< tripled (C0): the curve passes through p with a tangent jump
  double level = no_level; ///< mesh control parameter (target tree level), or no_level
};

/// An interior control point (the paper's third type): refines the tree around p.
struct InteriorControl {
  P2 p = P2::Zero();
  double level = 0.0;
  double radius = 0.0;  ///< influence radius in mesh units; 0 = only the cell containing p
};

/// One closed loop. Parameter t in [0, n_pieces()): piece floor(t), local u = t - floor(t).
struct Loop {
  std::vector<Bezier> pieces;       ///< pieces[i][3] == pieces[(i+1) % n][0]
  std::vector<std::uint8_t> corner; ///< corner[i]: the junction at the start of piece i is a corner
  std::vector<double> level;        ///< control level at the start of piece i, or no_level
  std::string name;                 ///< for messages, e.g. "path 2, subpath 1"

  std::size_t n_pieces() const { return pieces.size(); }
};

/// Everything a 2D input file says: loops, interior control points, default options.
struct Domain {
  std::vector<Loop> loops;
  std::vector<InteriorControl> interior;
  double default_level = no_level;  ///< from the file's options, if any
  std::string source;               ///< file name, for messages
};

/// A closed uniform cubic B-spline over `cps` (corner points tripled, as the paper's footnote),
/// converted exactly to Bezier pieces. Zero-length pieces are dropped.
Loop loop_from_bspline(const std::vector<ControlPoint>& cps, const std::string& name);

/// A loop from consecutive cubic Bezier pieces (closing gap must be zero). Junctions whose
/// tangent directions differ by more than `corner_angle_deg` become corners.
Loop loop_from_beziers(std::vector<Bezier> pieces, const std::string& name, double corner_angle_deg = 1.0);

/// A polygon: every vertex a corner, every edge a straight cubic piece.
Loop loop_from_polygon(const std::vector<P2>& vertices, const std::string& name);

/// The control polygon of the closed uniform B-spline behind loop_from_bspline: corner points
/// tripled (paper footnote). Point j of the result is the curve's control point for knot j.
std::vector<P2> expand_corners(const std::vector<ControlPoint>& cps);

/// Slow twin of loop_from_bspline: de Boor's algorithm on the expanded control polygon `q`
/// (closed, uniform integer knots; segment i, t in [i, i+1], uses q[i-1..i+2]).
P2 bspline_point_ref(const std::vector<P2>& q, double t);

}  // namespace febemesh::dim2
