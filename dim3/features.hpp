#pragma once
// Sharp features of a closed oriented surface: the 3D counterpart of the paper's corners
// (tripled knots). Feature edges: the normals of the two triangles differ by more than
// `angle_deg` (default 30 deg away from flat). Corners: vertices where 1 or >= 3 feature edges
// meet, where a feature line turns by more than `turn_deg`, or tips of sharp cones (no feature
// edge, angle defect 2 pi - sum of angles above `cone_deg`). Feature edges chain into lines
// between corners (or closed loops), which the boundary octants snap to.

#include <cstdint>
#include <vector>

#include "dim3/surface.hpp"

namespace febemesh::dim3 {

struct FeatureOptions {
  double angle_deg = 30.0;
  double turn_deg = 30.0;
  double cone_deg = 60.0;
};

/// A chain of feature edges: vertices[i]-vertices[i+1] is edges[i]; closed loops repeat
/// the first vertex at the end.
struct FeatureLine {
  std::vector<std::int32_t> vertices;
  std::vector<std::int32_t> edges;
  std::vector<P3> points;
  bool closed = false;
};

class Features {
 public:
  Features() = default;
  /// Requires a closed manifold surface (every edge with two triangles).
  explicit Features(const Surface& s, FeatureOptions options = {});

  /// Angle between the normals of the two triangles at edge e (0 = flat), radians.
  double dihedral(std::int32_t e) const { return dihedral_[e]; }
  bool is_feature_edge(std::int32_t e) const { return edge_index_[e] >= 0; }
  /// Position of edge e in feature_edges(), or -1.
  std::int32_t feature_edge_index(std::int32_t e) const { return edge_index_[e]; }
  /// Feature edges (surface edge ids), ascending.
  const std::vector<std::int32_t>& feature_edges() const { return edges_; }
  int n_feature_edges() const { return static_cast<int>(edges_.size()); }
  /// Number of feature edges at vertex v.
  int feature_degree(std::int32_t v) const { return degree_[v]; }

  bool is_corner(std::int32_t v) const { return corner_index_[v] >= 0; }
  std::int32_t corner_index(std::int32_t v) const { return corner_index_[v]; }
  /// Corner vertices (surface vertex ids), ascending.
  const std::vector<std::int32_t>& corners() const { return corners_; }
  const std::vector<P3>& corner_points() const { return corner_points_; }
  int n_corners() const { return static_cast<int>(corners_.size()); }

  const std::vector<FeatureLine>& lines() const { return lines_; }
  /// Line holding feature edge k (an index into feature_edges()).
  std::int32_t line_of(std::int32_t k) const { return line_of_[k]; }
  /// Share of the vertices where feature lines end (feature degree 1, or 3 and more) that are
  /// free ends (degree 1: a line stops in the middle of smooth surface); 0 when there are none.
  /// 0.69 on elephant.off's coarsely faceted skin, whose "features" are facet creases that
  /// start and stop anywhere; 0-0.08 on the machined parts, whose lines end where others meet.
  double free_end_share() const;

  struct LinePoint {
    P3 point = P3::Zero();
    double distance = 0.0;
    std::int32_t segment = -1;  ///< index into the line's edges
    double t = 0.0;             ///< along the segment, 0..1
  };
  /// Closest point of feature line `line` to p.
  LinePoint closest_on_line(std::int32_t line, const P3& p) const;
  /// Nearest corner to p (index into corners()) and its distance; corner = -1 if none.
  struct CornerHit {
    std::int32_t corner = -1;
    double distance = 0.0;
  };
  CornerHit nearest_corner(const P3& p) const;

 private:
  std::vector<double> dihedral_;
  std::vector<std::int32_t> edge_index_, edges_, degree_;
  std::vector<std::int32_t> corner_index_, corners_;
  std::vector<P3> corner_points_;
  std::vector<FeatureLine> lines_;
  std::vector<std::int32_t> line_of_;
};

}  // namespace febemesh::dim3
