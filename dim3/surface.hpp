#pragma once
// The 3D geometric model's topology: a triangle soup indexed into vertices, triangles, edges and
// their adjacency. No validity is assumed here (open, non-manifold and inconsistently oriented
// soups index fine); surface_checks.hpp decides what the mesher accepts.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>  // cross products

#include "core/box.hpp"

namespace febemesh::dim3 {

using P3 = Point<3>;
/// Vertex indices of a triangle, counter-clockwise seen from outside once oriented.
using Triangle = std::array<std::int32_t, 3>;
/// Vertex indices of an edge, smaller first.
using Edge = std::array<std::int32_t, 2>;

/// What a reader produces: coordinates and triangles, indices already checked to be in range.
struct TriangleSoup {
  std::vector<P3> vertices;
  std::vector<Triangle> triangles;
};

class Surface {
 public:
  Surface() = default;
  /// Indexes `soup`. Requires every index in [0, vertices.size()) (readers check it).
  explicit Surface(TriangleSoup soup);

  const std::vector<P3>& vertices() const { return vertices_; }
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<Edge>& edges() const { return edges_; }
  int n_vertices() const { return static_cast<int>(vertices_.size()); }
  int n_triangles() const { return static_cast<int>(triangles_.size()); }
  int n_edges() const { return static_cast<int>(edges_.size()); }
  /// Vertices used by at least one triangle (unused ones do not count in the topology).
  int n_used_vertices() const { return n_used_vertices_; }

  const P3& vertex(std::int32_t v) const { return vertices_[v]; }
  const Triangle& triangle(std::int32_t t) const { return triangles_[t]; }
  const Edge& edge(std::int32_t e) const { return edges_[e]; }
  /// Edge of triangle t from corner i to corner (i + 1) % 3.
  std::int32_t triangle_edge(std::int32_t t, int i) const { return triangle_edges_[t][i]; }
  /// Triangles around edge e, ascending.
  std::span<const std::int32_t> edge_triangles(std::int32_t e) const;
  /// Triangles around vertex v, ascending.
  std::span<const std::int32_t> vertex_triangles(std::int32_t v) const;
  /// Edges at vertex v, ascending.
  std::span<const std::int32_t> vertex_edges(std::int32_t v) const;
  /// Edge joining a and b, or -1.
  std::int32_t find_edge(std::int32_t a, std::int32_t b) const;
  /// The triangle across edge e from t when e has exactly two triangles, else -1.
  std::int32_t opposite_triangle(std::int32_t e, std::int32_t t) const;

  /// Connected components through shared edges; component ids ordered by smallest triangle.
  int n_components() const { return n_components_; }
  std::int32_t component(std::int32_t t) const { return component_[t]; }

  /// V - E + F over used vertices (2 - 2g per closed orientable component).
  int euler_characteristic() const;
  /// Signed volume enclosed (divergence theorem); > 0 when normals point outward.
  double volume() const;
  /// Signed volume of one component.
  double component_volume(std::int32_t c) const;
  double area() const;
  double triangle_area(std::int32_t t) const;
  /// Unit normal by the right-hand rule (zero for a zero-area triangle).
  P3 normal(std::int32_t t) const;
  Box<3> bounding_box() const { return bbox_; }

  /// Does triangle t run through edge e from edge(e)[0] to edge(e)[1]?
  bool runs_forward(std::int32_t t, std::int32_t e) const;
  /// Reverses the triangles whose flag is set (and re-indexes).
  void flip(const std::vector<bool>& which);

 private:
  void build();

  std::vector<P3> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<Edge> edges_;
  std::vector<std::array<std::int32_t, 3>> triangle_edges_;
  std::vector<std::int32_t> edge_tri_offset_, edge_tri_;      // CSR: edge -> triangles
  std::vector<std::int32_t> vertex_tri_offset_, vertex_tri_;  // CSR: vertex -> triangles
  std::vector<std::int32_t> vertex_edge_offset_, vertex_edge_;
  std::vector<std::int32_t> component_;
  int n_components_ = 0;
  int n_used_vertices_ = 0;
  Box<3> bbox_ = Box<3>::empty();
};

}  // namespace febemesh::dim3
