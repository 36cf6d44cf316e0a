#include "dim3/missed_surface.hpp"

#include <algorithm>
#include <cmath>

#include "dim3/aabb_tree.hpp"

namespace febemesh::dim3 {

std::vector<MissedPoint> missed_surface(const Mesh<3>& m, const SurfaceBoundary& s, double spacing,
                                        const std::function<double(const Point<3>&)>& allowance) {
  using P3 = Point<3>;
  std::vector<MissedPoint> out;
  std::vector<Triangle> be;
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    if (m.interface.type[e] != ElemType::Tri3) continue;
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    be.push_back({v[0].v, v[1].v, v[2].v});
  }
  if (be.empty() || !(spacing > 0)) return out;
  const AabbTree tree(m.points, be);
  const auto& x = s.vertices();
  for (const Triangle& t : s.triangles()) {
    const P3 &a = x[t[0]], &b = x[t[1]], &c = x[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = static_cast<int>(std::clamp(std::ceil(longest / spacing), 1.0, 256.0));
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const P3 p = a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a);
        const double d = std::sqrt(tree.closest(p).distance2);
        if (d > allowance(p)) out.push_back({p, d});
      }
  }
  return out;
}

}  // namespace febemesh::dim3
