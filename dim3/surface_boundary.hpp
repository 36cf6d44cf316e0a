#pragma once
// The 3D boundary (DESIGN.md, "the seam"): a closed, oriented triangle surface with its AABB
// tree and sharp features, answering what the octree pipeline asks of the boundary.
//
// Level field (control_level): the largest of
//   - the global level (set_global_level),
//   - global + feature_extra_levels where the box meets a triangle touching a feature edge or
//     corner,
//   - the curvature level of every triangle the box meets: log2(root side * kappa / arc), so
//     that a cell spans at most `arc` radians of the surface's bending; kappa of an edge is its
//     dihedral angle / the distance between its triangles' centroids (smooth edges only),
//     averaged at each vertex, and a triangle's kappa is the mean of its vertices',
//   - the thickness level of every triangle the box meets: log2(root side * thickness_cells /
//     thickness), the thickness measured along the inward normal (thickness(t)), capped by
//     thickness_max_level (set_thickness_level),
// the others capped by max_level (set_max_level).

#include <cmath>
#include <string>
#include <vector>

#include "core/boundary.hpp"
#include "dim3/aabb_tree.hpp"
#include "dim3/features.hpp"
#include "dim3/surface.hpp"

namespace febemesh::dim3 {

struct SurfaceOptions {
  FeatureOptions features;
  double global_level = 3.0;
  double max_level = 8.0;
  double feature_extra_levels = 1.0;
  /// Experiment (diagnose3d --feature-at-edges), off: the feature level only where the box meets
  /// a feature edge or contains a corner, not on every box meeting a triangle that touches one
  /// (on a coarse tessellation those triangles cover whole thin sheets: rotor's blades).
  /// Measured (diagnose3d, first tree, leaves / raw inverted tets, off -> on): rotor L6 407,576
  /// / 25,038 -> 289,472 / 3,125; but at level 4 anchor 13,280 / 1,131 -> 11,152 / 2,021,
  /// fandisk 9,472 / 1,964 -> 9,192 / 2,005, spool 12,608 / 106 -> 9,696 / 683 (coarser next to
  /// the features, more folds): not a default.
  bool feature_level_at_edges = false;
  double arc = 0.5;  ///< radians of bending one cell may span
  /// Octants wanted across the thickness of the solid (ray from each triangle inwards); 0 = off.
  /// Off by default: measured at level 4 it refines spool and rotor where the boundary octants
  /// then fold (spool valid without, invalid with), and elephant's topology is not fixed by it.
  /// mesh3d sets it (Options3d::thickness_cells, thin_retry_cells): with it, no buffer rule.
  double thickness_cells = 0.0;
  double thickness_max_level = 8.0;  ///< cap of the thickness level (set_thickness_level)
  /// The thickness level from a grid of rays over each triangle (thickness_samples), each
  /// applying near its own point, instead of one value per triangle from its centroid and
  /// vertices: a large triangle facing a sheet that comes near it at one place only (rotor.off's
  /// outer wall, a 27-degree chord of its cylinder over the inner one: 0.0034 thick where the
  /// four rays see 0.0081) gets the finer level there and nowhere else.
  bool thickness_sampled = false;
  /// The root cube's shift from its centred place, in shares of its side per axis (0: the
  /// bounding box's centre). A face of the surface parallel to a lattice plane and just outside
  /// it makes flat boundary octants on it (rotor.off's rim, 0.05 of a level-8 octant above
  /// one); a shift moves every lattice plane against the surface.
  P3 root_shift = P3::Zero();
  /// The root cube's side over its default (1.05 x the bounding box's largest extent), >= 1:
  /// Options3d::size sets it so that the octants of its level have that side.
  double root_scale = 1.0;
};

class SurfaceBoundary final : public Boundary<3> {
 public:
  /// Requires a surface that passed validate_surface() (closed, manifold, oriented outward).
  explicit SurfaceBoundary(Surface surface, SurfaceOptions options = {});
  /// The same with the surface's tree already built (validate_surface returns it).
  SurfaceBoundary(Surface surface, AabbTree tree, SurfaceOptions options = {});
  /// Reads, validates and orients `path`; throws InputError naming it.
  static SurfaceBoundary from_file(const std::string& path, SurfaceOptions options = {});

  // ---- Boundary<3> ----
  Box<3> bounding_box() const override { return surface_.bounding_box(); }
  Side classify(const Box<3>& box) const override;
  bool is_inside(const P3& p) const override;
  ClosestPoint<3> closest_point(const P3& p) const override;
  /// Local minima of the distance within max(3 d, d + 5% of the diagonal), d = the nearest.
  std::vector<ClosestPoint<3>> closest_points(const P3& p, int max_count) const override;
  bool segment_crosses(const P3& a, const P3& b) const override;
  /// segment_crosses(a, end) for a segment ending on the surface at `p`: `end` stops short of p
  /// by 1e-7 of the segment, and by 1e-9 of the diagonal at least. Stopping short by the share
  /// alone left a node 1e-5 from a sliver triangle (rotor.off's outer wall, 0.4 long) an end
  /// 1e-12 from its plane, within orient3d's tolerance: a Degenerate crossing, so its closest
  /// point was refused and its projection ran back 0.02 through the wall.
  bool crosses_before(const P3& a, const P3& p) const;
  double control_level(const Box<3>& box) const override;

  // ---- the model ----
  const Surface& surface() const { return surface_; }
  const std::vector<P3>& vertices() const { return surface_.vertices(); }
  const std::vector<Triangle>& triangles() const { return surface_.triangles(); }
  int n_components() const { return surface_.n_components(); }
  int euler_characteristic() const { return surface_.euler_characteristic(); }
  double volume() const { return surface_.volume(); }
  double area() const { return surface_.area(); }
  const Features& features() const { return features_; }
  const AabbTree& tree() const { return tree_; }
  /// The options as they are now (the levels set since construction included).
  const SurfaceOptions& options() const { return options_; }
  /// Smallest cube around the bounding box, enlarged by 5% and by SurfaceOptions::root_scale,
  /// same centre, shifted by SurfaceOptions::root_shift.
  Box<3> root_box() const;
  /// The side of an octant at `level`: root_box()'s x extent / 2^level.
  double octant_side(int level) const { return root_box().extent()[0] / std::ldexp(1.0, level); }
  /// SurfaceOptions::root_scale (>= 1); the curvature and thickness levels follow the new side.
  void set_root_scale(double scale);
  double root_scale() const { return options_.root_scale; }
  /// SurfaceOptions::root_shift; the trees built after it use the moved lattice.
  void set_root_shift(const P3& shift) { options_.root_shift = shift; }
  const P3& root_shift() const { return options_.root_shift; }

  void set_global_level(double level) { options_.global_level = level; }
  void set_max_level(double level) { options_.max_level = level; }
  /// The feature level's levels above the global one (SurfaceOptions::feature_extra_levels).
  void set_feature_extra_levels(double levels) { options_.feature_extra_levels = levels; }
  double feature_extra_levels() const { return options_.feature_extra_levels; }
  /// The thickness level's cells across (0 = off) and its cap; computes the thicknesses on
  /// first use (not thread-safe: call before the level field is read).
  void set_thickness_level(double cells, double max_level);
  /// SurfaceOptions::thickness_sampled (applies from the next set_thickness_level).
  void set_thickness_sampled(bool on) { options_.thickness_sampled = on; }
  /// thickness(t) of every triangle, computed once.
  const std::vector<double>& thicknesses();
  /// centroid_thickness(t) of every triangle, computed once.
  const std::vector<double>& centroid_thicknesses();
  /// Share of the surface's area whose thickness (thickness(t)) is below `h`.
  double thin_share(double h);
  /// The level whose octants put `cells` of them across the thin parts: the area-weighted
  /// median, over the triangles thinner than `cells` octants of `level`, of log2(root side x
  /// cells / thickness(t)); -infinity where none is.
  double thin_parts_level(double cells, int level);
  double global_level() const { return options_.global_level; }
  double max_level() const { return options_.max_level; }
  /// Thickness of the solid behind triangle t: the smallest of the distances from its centroid
  /// and from its three vertices straight inwards (along -normal(t)) to where that ray leaves
  /// the solid (thickness_from); infinity when no ray does. One value at the centroid misses a
  /// taper: a lip 0.022 thick at one end of a triangle and 0.010 at the other (spool.off).
  double thickness(std::int32_t t) const;
  /// The distance from `p` (on triangle t) along -normal(t) to the first surface point the ray
  /// meets, when the ray leaves the solid there; infinity when it meets nothing or first enters
  /// the solid (it started outside: a vertex on an edge sharper than 90 degrees). Triangles
  /// around `vertex` (-1: none; p is that vertex) and hits within 1e-7 of the diagonal are not
  /// counted.
  double thickness_from(std::int32_t t, const P3& p, std::int32_t vertex) const;
  /// thickness_from its centroid alone (the island refinement's thin test, Options3d::
  /// thin_cells, was measured with it: with thickness(t) elephant L4 lost 1.25% instead of 0.34%).
  double centroid_thickness(std::int32_t t) const;
  /// Curvature level of triangle t (before the global level and the cap).
  double curvature_level(std::int32_t t) const { return curvature_level_[t]; }

  /// Inside test by the pseudo-normal at the closest point (Baerentzen-Aanaes), the slow twin
  /// of the ray-parity is_inside().
  bool is_inside_ref(const P3& p) const;

 private:
  BoundaryLocation locate(std::int32_t t, const TrianglePoint& tp) const;
  /// A feature edge of triangle t meets `box`, or a corner of t lies in it.
  bool feature_in_box(std::int32_t t, const Box<3>& box) const;
  ClosestPoint<3> to_closest(const AabbTree::Closest& c, const P3& p) const;
  P3 pseudo_normal(std::int32_t t, TriangleRegion region) const;

  Surface surface_;
  SurfaceOptions options_;
  AabbTree tree_;
  Features features_;
  std::vector<double> curvature_;        ///< per triangle: the curvature behind its level (0: flat)
  std::vector<double> curvature_level_;
  std::vector<double> thickness_;        ///< thickness(t), when computed
  std::vector<double> centroid_thickness_;  ///< centroid_thickness(t), when computed
  std::vector<double> thickness_level_;  ///< -inf where thickness_cells is off or nothing is behind
  /// With thickness_sampled: per triangle, its samples [sample_begin_[t], sample_begin_[t + 1])
  /// of sample_point_ / sample_level_, each applying within sample_reach_[t] of its point.
  std::vector<std::int32_t> sample_begin_;
  std::vector<P3> sample_point_;
  std::vector<double> sample_level_;
  std::vector<double> sample_reach_;
  double root_side_ = 0.0;
  std::vector<bool> near_feature_;
  double diagonal_ = 0.0;
};

}  // namespace febemesh::dim3
