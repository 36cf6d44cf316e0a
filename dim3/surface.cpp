#include "dim3/surface.hpp"

#include <algorithm>
#include <numeric>
#include <tuple>
#include <utility>

#include "core/error.hpp"

namespace febemesh::dim3 {

namespace {

/// Compressed rows from (key, value) pairs; values within a row ascending.
void build_csr(int n_keys, std::vector<std::pair<std::int32_t, std::int32_t>> pairs,
               std::vector<std::int32_t>& offset, std::vector<std::int32_t>& value) {
  std::sort(pairs.begin(), pairs.end());
  offset.assign(n_keys + 1, 0);
  for (const auto& [k, v] : pairs) ++offset[k + 1];
  std::partial_sum(offset.begin(), offset.end(), offset.begin());
  value.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) value[i] = pairs[i].second;
}

std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

}  // namespace

Surface::Surface(TriangleSoup soup)
    : vertices_(std::move(soup.vertices)), triangles_(std::move(soup.triangles)) {
  build();
}

void Surface::build() {
  const int nv = n_vertices();
  const int nt = n_triangles();
  bbox_ = Box<3>::empty();
  std::vector<bool> used(nv, false);
  for (const Triangle& t : triangles_)
    for (std::int32_t v : t) {
      MESH_ASSERT(v >= 0 && v < nv, "vertex index " << v << " out of range");
      used[v] = true;
    }
  n_used_vertices_ = static_cast<int>(std::count(used.begin(), used.end(), true));
  for (int v = 0; v < nv; ++v)
    if (used[v]) bbox_.expand(vertices_[v]);

  // Edges: sort (min, max, triangle, slot) and merge equal vertex pairs.
  std::vector<std::tuple<std::int32_t, std::int32_t, std::int32_t, int>> half;
  half.reserve(3 * nt);
  for (std::int32_t t = 0; t < nt; ++t)
    for (int i = 0; i < 3; ++i) {
      const std::int32_t a = triangles_[t][i], b = triangles_[t][(i + 1) % 3];
      half.emplace_back(std::min(a, b), std::max(a, b), t, i);
    }
  std::sort(half.begin(), half.end());
  edges_.clear();
  triangle_edges_.assign(nt, {-1, -1, -1});
  std::vector<std::pair<std::int32_t, std::int32_t>> edge_tri, vertex_tri, vertex_edge;
  for (std::size_t i = 0; i < half.size(); ++i) {
    const auto& [a, b, t, slot] = half[i];
    if (i == 0 || std::get<0>(half[i - 1]) != a || std::get<1>(half[i - 1]) != b) {
      edges_.push_back({a, b});
      const std::int32_t e = static_cast<std::int32_t>(edges_.size()) - 1;
      vertex_edge.emplace_back(a, e);
      if (b != a) vertex_edge.emplace_back(b, e);
    }
    const std::int32_t e = static_cast<std::int32_t>(edges_.size()) - 1;
    triangle_edges_[t][slot] = e;
    edge_tri.emplace_back(e, t);
  }
  // A triangle that uses an edge twice (degenerate) lists once per use; keep rows unique.
  std::sort(edge_tri.begin(), edge_tri.end());
  edge_tri.erase(std::unique(edge_tri.begin(), edge_tri.end()), edge_tri.end());
  for (std::int32_t t = 0; t < nt; ++t)
    for (std::int32_t v : triangles_[t]) vertex_tri.emplace_back(v, t);
  std::sort(vertex_tri.begin(), vertex_tri.end());
  vertex_tri.erase(std::unique(vertex_tri.begin(), vertex_tri.end()), vertex_tri.end());
  build_csr(n_edges(), std::move(edge_tri), edge_tri_offset_, edge_tri_);
  build_csr(nv, std::move(vertex_tri), vertex_tri_offset_, vertex_tri_);
  build_csr(nv, std::move(vertex_edge), vertex_edge_offset_, vertex_edge_);

  // Components by union-find over shared edges, renumbered by smallest triangle.
  std::vector<std::int32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0);
  for (std::int32_t e = 0; e < n_edges(); ++e) {
    const auto tris = edge_triangles(e);
    for (std::size_t k = 1; k < tris.size(); ++k) {
      const std::int32_t ra = find_root(parent, tris[0]), rb = find_root(parent, tris[k]);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  component_.assign(nt, -1);
  std::vector<std::int32_t> id_of_root(nt, -1);
  n_components_ = 0;
  for (std::int32_t t = 0; t < nt; ++t) {
    const std::int32_t r = find_root(parent, t);
    if (id_of_root[r] < 0) id_of_root[r] = n_components_++;
    component_[t] = id_of_root[r];
  }
}

std::span<const std::int32_t> Surface::edge_triangles(std::int32_t e) const {
  return {edge_tri_.data() + edge_tri_offset_[e],
          static_cast<std::size_t>(edge_tri_offset_[e + 1] - edge_tri_offset_[e])};
}

std::span<const std::int32_t> Surface::vertex_triangles(std::int32_t v) const {
  return {vertex_tri_.data() + vertex_tri_offset_[v],
          static_cast<std::size_t>(vertex_tri_offset_[v + 1] - vertex_tri_offset_[v])};
}

std::span<const std::int32_t> Surface::vertex_edges(std::int32_t v) const {
  return {vertex_edge_.data() + vertex_edge_offset_[v],
          static_cast<std::size_t>(vertex_edge_offset_[v + 1] - vertex_edge_offset_[v])};
}

std::int32_t Surface::find_edge(std::int32_t a, std::int32_t b) const {
  const Edge key{std::min(a, b), std::max(a, b)};
  for (std::int32_t e : vertex_edges(key[0]))
    if (edges_[e] == key) return e;
  return -1;
}

std::int32_t Surface::opposite_triangle(std::int32_t e, std::int32_t t) const {
  const auto tris = edge_triangles(e);
  if (tris.size() != 2) return -1;
  return tris[0] == t ? tris[1] : tris[0];
}

int Surface::euler_characteristic() const {
  return n_used_vertices_ - n_edges() + n_triangles();
}

namespace {
double tet_volume6(const P3& a, const P3& b, const P3& c) { return a.dot(b.cross(c)); }
}  // namespace

double Surface::volume() const {
  // Relative to the box centre: fewer cancellation digits lost than relative to the origin.
  const P3 o = bbox_.center();
  double v = 0.0;
  for (const Triangle& t : triangles_)
    v += tet_volume6(vertices_[t[0]] - o, vertices_[t[1]] - o, vertices_[t[2]] - o);
  return v / 6.0;
}

double Surface::component_volume(std::int32_t c) const {
  const P3 o = bbox_.center();
  double v = 0.0;
  for (std::int32_t t = 0; t < n_triangles(); ++t)
    if (component_[t] == c) {
      const Triangle& tr = triangles_[t];
      v += tet_volume6(vertices_[tr[0]] - o, vertices_[tr[1]] - o, vertices_[tr[2]] - o);
    }
  return v / 6.0;
}

double Surface::triangle_area(std::int32_t t) const {
  const Triangle& tr = triangles_[t];
  return 0.5 * (vertices_[tr[1]] - vertices_[tr[0]]).cross(vertices_[tr[2]] - vertices_[tr[0]]).norm();
}

double Surface::area() const {
  double a = 0.0;
  for (std::int32_t t = 0; t < n_triangles(); ++t) a += triangle_area(t);
  return a;
}

P3 Surface::normal(std::int32_t t) const {
  const Triangle& tr = triangles_[t];
  const P3 n = (vertices_[tr[1]] - vertices_[tr[0]]).cross(vertices_[tr[2]] - vertices_[tr[0]]);
  const double len = n.norm();
  return len > 0.0 ? P3(n / len) : P3::Zero();
}

bool Surface::runs_forward(std::int32_t t, std::int32_t e) const {
  for (int i = 0; i < 3; ++i)
    if (triangle_edges_[t][i] == e) return triangles_[t][i] == edges_[e][0];
  MESH_ASSERT(false, "edge " << e << " is not on triangle " << t);
  return false;
}

void Surface::flip(const std::vector<bool>& which) {
  MESH_ASSERT(which.size() == triangles_.size(), which.size() << " flags");
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    if (which[t]) std::swap(triangles_[t][1], triangles_[t][2]);
  build();
}

}  // namespace febemesh::dim3
