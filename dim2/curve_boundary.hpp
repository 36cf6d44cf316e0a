#pragma once
// The 2D boundary (paper): a Domain of closed cubic B-spline loops behind the core Boundary<2>
// interface, with the extra curve queries the 2D pipeline uses.
//
// Construction checks the whole input (domain_checks.hpp), derives nesting (a loop inside an
// odd number of others is a hole) and orients every loop so that the solid lies on its left:
// outer loops counter-clockwise, holes clockwise, whatever the file said.
//
// Parameters: loop i, t in [0, n_pieces) (piece floor(t), Bezier parameter t - floor(t)).
//
// Control levels (control_level(box)): the largest of
//   - the global level (Domain::default_level, or set_global_level);
//   - interior control points whose centre is within their radius of the box;
//   - the curve's levels: levels given at junctions are interpolated linearly in t between
//     consecutive junctions that have one (constant if only one junction has a level); the
//     value is taken over the parts of pieces that meet the box;
//   - AUTOMATIC, only when none of the above is given anywhere: for each piece meeting the box,
//     the smallest level L with cell size h_L = root_side / 2^L such that
//       h_L <= 0.3 R      (R = smallest radius of curvature on the piece, 33 samples), and
//       h_L <= d / 2      (d = local thickness: the smallest distance from a sample of the piece
//                          to another local minimum of the distance along the boundary, i.e.
//                          across a thin part, a slot, or to a nearby loop or an acute corner),
//     capped by max_level() (default 12). Cells away from the curve get level 0.
//   - with given levels, the thickness rule (features thinner than the quadrants are refined
//     until resolved) and the curvature rule h_L <= 0.3 R still apply, at most 4 levels beyond
//     the given level.
// Levels are relative to root_box(), the tree's root: the smallest square around
// bounding_box() enlarged by 5% (and by set_root_scale).

#include <cstdint>
#include <vector>

#include "core/boundary.hpp"
#include "dim2/bezier.hpp"
#include "dim2/curve_model.hpp"

namespace febemesh::dim2 {

struct CurveCorner {
  int loop = -1;
  double t = 0.0;
  P2 point = P2::Zero();
  double angle_deg = 0.0;  ///< interior angle, measured inside the solid (< 180: convex)
};

class CurveBoundary final : public Boundary<2> {
 public:
  /// Checks and orients the domain; throws InputError for invalid input.
  explicit CurveBoundary(Domain domain);

  // --- Boundary<2> ------------------------------------------------------------------------
  Box<2> bounding_box() const override { return bbox_; }
  Side classify(const Box<2>& box) const override;
  bool is_inside(const P2& p) const override;  ///< nonzero winding over the oriented loops
  /// Global search over pieces (BVH on control boxes, Bernstein lower bounds of the squared
  /// distance), then safeguarded Newton on (P(u) - p) . P'(u) = 0 (paper eq. 1). Corners are
  /// candidates: where.kind = Corner and where.feature = corner index when the result is one.
  ClosestPoint<2> closest_point(const P2& p) const override;
  /// All local minima of the distance along the loops, nearest first (ties by loop, t).
  std::vector<ClosestPoint<2>> closest_points(const P2& p, int max_count) const override;
  /// Open segment: touches within 1e-10 of the domain size of a or b are ignored.
  bool segment_crosses(const P2& a, const P2& b) const override;
  double control_level(const Box<2>& box) const override;
  /// control_level with the thickness and curvature floors allowed up to `floor_boost` levels
  /// beyond a given level instead of floor_boost_default (control_level's).
  double control_level(const Box<2>& box, double floor_boost) const;
  /// How far beyond a given level the floors go (the rule above).
  static constexpr double floor_boost_default = 4.0;

  // --- 2D API -----------------------------------------------------------------------------
  const Domain& domain() const { return domain_; }
  const std::vector<Loop>& loops() const { return domain_.loops; }
  int n_loops() const { return int(domain_.loops.size()); }
  bool is_hole(int loop) const { return hole_[std::size_t(loop)] != 0; }
  int nesting_depth(int loop) const { return depth_[std::size_t(loop)]; }
  int n_components() const;  ///< loops that are not holes
  int n_holes() const;
  double area() const;                ///< solid area, positive
  double signed_area(int loop) const;  ///< after orientation: > 0 outer, < 0 hole
  double length(int loop) const;
  P2 evaluate(int loop, double t) const;
  P2 derivative(int loop, double t) const;
  P2 tangent(int loop, double t) const;
  double curvature(int loop, double t) const;
  const std::vector<CurveCorner>& corners() const { return corners_; }
  /// Index into corners() of the corner at the start of piece `piece`, or -1.
  int corner_index(int loop, std::size_t piece) const;
  /// The curve's interpolated control level at (loop, t), or no_level.
  double level_at(int loop, double t) const;
  /// Parameter reached by walking arc length s from t (backwards if s < 0).
  double advance(int loop, double t, double s) const;
  /// Arc length from t0 forward to t1, periodic.
  double arc_length(int loop, double t0, double t1) const;
  /// The closed segment [a, b] touches the curve.
  bool segment_touches(const P2& a, const P2& b) const;

  Box<2> root_box() const;
  /// The root square's side over its default (1.05 x the largest extent), >= 1 (mesh2d's --size,
  /// core level_for_size): the automatic and floor levels follow the new side, and the levels
  /// the file gives (on the curve, at interior points, its default) rise by log2(scale), so that
  /// their quadrants are no larger than in the default square.
  void set_root_scale(double scale);
  double root_scale() const { return root_scale_; }
  void set_global_level(double level) { global_level_ = level; }
  double global_level() const { return global_level_; }
  void set_max_level(int level) { max_level_ = level; }
  int max_level() const { return max_level_; }
  /// True when no level is given anywhere, so control_level uses the automatic rule.
  bool is_automatic() const;
  /// The uncapped automatic level of a piece (see the rule above).
  double automatic_level(int loop, std::size_t piece) const;

  /// Slow twin of closest_point: dense sampling (`samples` per piece) then golden-section polish.
  ClosestPoint<2> closest_point_ref(const P2& p, int samples = 200) const;
  /// Slow twin of classify: same answer from brute force over all pieces, no BVH.
  Side classify_ref(const Box<2>& box) const;

  /// Quadrants across the thinnest feature. With the buffer rule (0.35 of a size on each side)
  /// and an arbitrary lattice offset, a straight stroke of width w holds an edge-connected row of
  /// interior quadrants of size s only when w >= 2.7 s, and a diagonal one when w >= ~3.5 s.
  static constexpr double quadrants_across_feature = 4.0;
  /// Largest quadrant size along the curve, in radii of curvature: 0.3 keeps a chord's sagitta
  /// below 1.2% of its length (h^2 / 8R), so a tight bend (an airfoil's leading edge) is never
  /// cut by one chord of a coarse cell.
  static constexpr double cells_per_radius = 0.3;

 private:
  struct Piece {
    Bezier q;
    CubicPoly poly;
    Box<2> box;  ///< control box
    std::int32_t loop;
    std::int32_t index;
  };
  struct Node {
    Box<2> box;
    std::int32_t first = 0, count = 0;  ///< leaf: pieces_[first, first + count)
    std::int32_t left = -1, right = -1;
  };
  struct Candidate {
    double d2;
    std::int32_t rec;
    double u;
  };

  int build_bvh(int first, int last);
  void piece_minimum(int rec, const P2& p, double& best_d2, int& best_rec, double& best_u) const;
  void piece_local_minima(int rec, const P2& p, double bound_d2, std::vector<Candidate>& out) const;
  void junction_minima(int rec, const P2& p, std::vector<Candidate>& out) const;
  ClosestPoint<2> make_result(int rec, double u, const P2& p) const;
  bool piece_meets_box(int rec, const Box<2>& box) const;
  bool segment_hits(const P2& a, const P2& b, double s_lo, double s_hi) const;
  double local_thickness(const P2& s) const;
  /// The same, ignoring minima on piece `piece` of `loop` and its two neighbours, so that a
  /// corner is not taken for a thin feature.
  double feature_thickness(const P2& s, int loop, int piece) const;
  void compute_automatic_levels();

  template <typename NodeTest, typename LeafVisit>
  void traverse(NodeTest&& test, LeafVisit&& visit) const;
  void build_ray_bands();

  Domain domain_;
  std::vector<std::uint8_t> hole_;
  std::vector<int> depth_;
  std::vector<double> signed_area_, length_;
  std::vector<Piece> pieces_;             ///< in BVH order
  std::vector<std::vector<int>> rec_of_;  ///< [loop][piece] -> index into pieces_
  std::vector<Node> nodes_;
  /// is_inside's index: band_y_ holds the pieces' distinct control-box y bounds, ascending; a
  /// point with j of them below its y can be crossed (ray_crossings != 0) only by the pieces
  /// band_piece_[band_first_[j] .. band_first_[j + 1]), those with lo.y < y <= hi.y. Empty
  /// (the BVH answers) when it would be large or a bound is not finite.
  std::vector<double> band_y_;
  std::vector<std::int32_t> band_first_, band_piece_;
  std::vector<CurveCorner> corners_;
  std::vector<std::vector<int>> corner_of_;       ///< [loop][piece] -> corner index or -1
  std::vector<std::vector<int>> level_junctions_;  ///< per loop: junctions with a level, ascending
  std::vector<std::vector<double>> auto_level_;    ///< [loop][piece]
  /// [loop][piece]: the level the piece needs whatever was asked: cells no larger than a
  /// quarter of the feature thickness nor cells_per_radius x the smallest radius of curvature.
  std::vector<std::vector<double>> floor_level_;
  Box<2> bbox_;
  double scale_ = 1.0;  ///< largest extent of the bounding box
  double global_level_ = no_level;
  double root_scale_ = 1.0;
  double file_level_shift_ = 0.0;  ///< log2(root_scale_): added to the levels the file gives
  int max_level_ = 12;
  bool has_curve_levels_ = false;
};

}  // namespace febemesh::dim2
