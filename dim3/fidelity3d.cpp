#include "dim3/fidelity3d.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/quality.hpp"
#include "dim3/aabb_tree.hpp"

namespace febemesh::dim3 {

double surface_to_be_distance(const Mesh<3>& m, const SurfaceBoundary& s) {
  std::vector<Triangle> be;
  for (std::size_t e = 0; e < m.interface.size(); ++e)
    if (m.interface.type[e] == ElemType::Tri3) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
      be.push_back({v[0].v, v[1].v, v[2].v});
    }
  if (be.empty()) return 0.0;
  // Vertices and triangle centroids against an AABB tree of the BE mesh.
  const AabbTree tree(m.points, be);
  double d = 0.0;
  for (const P3& p : s.vertices()) d = std::max(d, std::sqrt(tree.closest(p).distance2));
  for (const Triangle& t : s.triangles()) {
    const P3 c = (s.vertices()[t[0]] + s.vertices()[t[1]] + s.vertices()[t[2]]) / 3.0;
    d = std::max(d, std::sqrt(tree.closest(c).distance2));
  }
  return d;
}

Fidelity3d measure_fidelity(const Mesh<3>& m, const SurfaceBoundary& s, int samples) {
  Fidelity3d f;
  f.surface_volume = s.volume();
  f.fe_volume = solid_measure<3>(m);
  f.volume_rel_error = f.surface_volume != 0 ? std::abs(f.fe_volume - f.surface_volume) / std::abs(f.surface_volume) : 0;

  // BE mesh -> surface: barycentric samples of every BE triangle; interface nodes.
  std::set<std::int32_t> nodes;
  const int n = std::max(samples, 1);
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    if (m.interface.type[e] != ElemType::Tri3) continue;
    const VertexId* v = m.interface.nodes(id);
    for (int k = 0; k < 3; ++k) nodes.insert(v[k].v);
    const P3 &a = m.points[v[0].v], &b = m.points[v[1].v], &c = m.points[v[2].v];
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const P3 p = a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a);
        f.be_to_surface = std::max(f.be_to_surface, s.closest_point(p).distance);
      }
  }
  for (std::int32_t v : nodes) f.max_node_distance = std::max(f.max_node_distance, s.closest_point(m.points[v]).distance);

  f.surface_to_be = surface_to_be_distance(m, s);
  f.hausdorff = std::max(f.be_to_surface, f.surface_to_be);
  const double diag = s.bounding_box().extent().norm();
  f.hausdorff_rel = diag > 0 ? f.hausdorff / diag : 0.0;
  return f;
}

}  // namespace febemesh::dim3
