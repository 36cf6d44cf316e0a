#include "dim3/features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "dim3/triangle_predicates.hpp"

namespace febemesh::dim3 {

namespace {

constexpr double kPi = 3.14159265358979323846;

double angle_between(const P3& a, const P3& b) {
  // atan2 of |a x b| and a.b: accurate near 0 and pi, unlike acos.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

Features::Features(const Surface& s, FeatureOptions options) {
  const double feature_angle = options.angle_deg * kPi / 180.0;
  const int ne = s.n_edges(), nv = s.n_vertices();
  dihedral_.assign(ne, 0.0);
  edge_index_.assign(ne, -1);
  degree_.assign(nv, 0);
  for (std::int32_t e = 0; e < ne; ++e) {
    const auto tris = s.edge_triangles(e);
    MESH_ASSERT(tris.size() == 2, "edge " << e << " has " << tris.size() << " triangles");
    dihedral_[e] = angle_between(s.normal(tris[0]), s.normal(tris[1]));
    if (dihedral_[e] > feature_angle) {
      edge_index_[e] = static_cast<std::int32_t>(edges_.size());
      edges_.push_back(e);
      ++degree_[s.edge(e)[0]];
      ++degree_[s.edge(e)[1]];
    }
  }

  // Corners.
  corner_index_.assign(nv, -1);
  const double turn = options.turn_deg * kPi / 180.0, cone = options.cone_deg * kPi / 180.0;
  for (std::int32_t v = 0; v < nv; ++v) {
    bool corner = degree_[v] == 1 || degree_[v] >= 3;
    if (degree_[v] == 2) {
      P3 dir[2];
      int k = 0;
      for (std::int32_t e : s.vertex_edges(v))
        if (is_feature_edge(e)) {
          const std::int32_t w = s.edge(e)[0] == v ? s.edge(e)[1] : s.edge(e)[0];
          dir[k++] = s.vertex(w) - s.vertex(v);
        }
      // Straight continuation: the two edges point in opposite directions (angle pi).
      corner = kPi - angle_between(dir[0], dir[1]) > turn;
    } else if (degree_[v] == 0 && !s.vertex_triangles(v).empty()) {
      double sum = 0.0;
      for (std::int32_t t : s.vertex_triangles(v)) {
        const Triangle& tr = s.triangle(t);
        const int i = tr[0] == v ? 0 : tr[1] == v ? 1 : 2;
        sum += angle_between(s.vertex(tr[(i + 1) % 3]) - s.vertex(v), s.vertex(tr[(i + 2) % 3]) - s.vertex(v));
      }
      corner = 2.0 * kPi - sum > cone;
    }
    if (corner) {
      corner_index_[v] = static_cast<std::int32_t>(corners_.size());
      corners_.push_back(v);
      corner_points_.push_back(s.vertex(v));
    }
  }

  // Lines: walk from corners and line ends first, then what is left are closed loops.
  line_of_.assign(edges_.size(), -1);
  auto next_edge = [&](std::int32_t v, std::int32_t from) {
    for (std::int32_t e : s.vertex_edges(v))
      if (e != from && is_feature_edge(e) && line_of_[edge_index_[e]] < 0) return e;
    return std::int32_t{-1};
  };
  auto walk = [&](std::int32_t start, std::int32_t first_edge) {
    FeatureLine line;
    line.vertices.push_back(start);
    std::int32_t v = start, e = first_edge;
    const std::int32_t id = static_cast<std::int32_t>(lines_.size());
    while (e >= 0) {
      line_of_[edge_index_[e]] = id;
      line.edges.push_back(e);
      v = s.edge(e)[0] == v ? s.edge(e)[1] : s.edge(e)[0];
      line.vertices.push_back(v);
      if (v == start) {
        line.closed = true;
        break;
      }
      if (is_corner(v) || degree_[v] != 2) break;
      e = next_edge(v, e);
    }
    for (std::int32_t w : line.vertices) line.points.push_back(s.vertex(w));
    lines_.push_back(std::move(line));
  };
  for (std::int32_t v = 0; v < nv; ++v)
    if (degree_[v] > 0 && (is_corner(v) || degree_[v] != 2))
      for (std::int32_t e = next_edge(v, -1); e >= 0; e = next_edge(v, -1)) walk(v, e);
  for (std::int32_t k = 0; k < n_feature_edges(); ++k)
    if (line_of_[k] < 0) walk(s.edge(edges_[k])[0], edges_[k]);
}

double Features::free_end_share() const {
  int ends = 0, free = 0;
  for (int d : degree_) {
    ends += d == 1 || d >= 3;
    free += d == 1;
  }
  return ends == 0 ? 0.0 : static_cast<double>(free) / ends;
}

Features::LinePoint Features::closest_on_line(std::int32_t line, const P3& p) const {
  const FeatureLine& l = lines_[line];
  LinePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < l.points.size(); ++i) {
    const double t = closest_on_segment(p, l.points[i], l.points[i + 1]);
    const P3 q = l.points[i] + t * (l.points[i + 1] - l.points[i]);
    const double d = (q - p).norm();
    if (d < best.distance) best = {q, d, static_cast<std::int32_t>(i), t};
  }
  return best;
}

Features::CornerHit Features::nearest_corner(const P3& p) const {
  CornerHit best;
  best.distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < corner_points_.size(); ++i) {
    const double d = (corner_points_[i] - p).norm();
    if (d < best.distance) best = {static_cast<std::int32_t>(i), d};
  }
  return best;
}

}  // namespace febemesh::dim3
