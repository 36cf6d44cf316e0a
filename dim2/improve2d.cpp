#include "dim2/improve2d.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace febemesh::dim2 {
namespace {

using P2 = Point<2>;

double cross(const P2& a, const P2& b, const P2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/// Smallest corner angle of polygon pts (CCW), degrees; -1 if any corner turns the wrong way.
double polygon_min_angle(const P2* pts, int n) {
  double best = 180.0;
  for (int k = 0; k < n; ++k) {
    const P2 &prev = pts[(k + n - 1) % n], &cur = pts[k], &next = pts[(k + 1) % n];
    if (cross(prev, cur, next) <= 0) return -1.0;
    const P2 a = prev - cur, b = next - cur;
    const double ang = std::atan2(std::abs(a[0] * b[1] - a[1] * b[0]), a.dot(b)) * 180.0 / M_PI;
    best = std::min(best, ang);
  }
  return best;
}

double tri_min_angle(const P2& a, const P2& b, const P2& c) {
  const P2 p[3] = {a, b, c};
  return polygon_min_angle(p, 3);
}

}  // namespace

double min_corner_angle_deg(const Mesh<2>& m, std::size_t e) {
  const ElemId id{static_cast<std::int32_t>(e)};
  const int n = m.solid.n_nodes_of(id);
  std::array<P2, 4> p;
  for (int k = 0; k < n; ++k) p[k] = m.points[m.solid.nodes(id)[k].v];
  return polygon_min_angle(p.data(), n);
}

ImproveStats improve_mesh(Mesh<2>& m, const std::vector<std::uint8_t>& locked, int rounds, const SlideFn& slide) {
  ImproveStats st;
  auto mesh_min = [&] {
    double q = 180.0;
    for (std::size_t e = 0; e < m.solid.size(); ++e) q = std::min(q, min_corner_angle_deg(m, e));
    return q;
  };
  st.min_angle_before = mesh_min();
  const std::size_t n_nodes = m.points.size();

  // Interface edges never flip (sorted keys, binary search).
  using EdgeKey = std::uint64_t;
  auto key_of = [](std::int32_t a, std::int32_t b) {
    return (static_cast<EdgeKey>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  };
  std::vector<EdgeKey> interface_edge;
  for (std::size_t e = 0; e < m.interface.size(); ++e) {
    const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
    interface_edge.push_back(key_of(v[0].v, v[1].v));
  }
  std::sort(interface_edge.begin(), interface_edge.end());

  // Flips are tried only on edges of elements below `good` degrees: the interior templates have
  // 45 degrees already, so flipping costs little beyond the boundary layer.
  const double good = 44.0;
  std::vector<double> angle(m.solid.size());
  struct HalfEdge {
    EdgeKey key;
    std::int32_t elem;
    int local;
  };
  std::vector<HalfEdge> half;
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t e = 0; e < m.solid.size(); ++e) angle[e] = min_corner_angle_deg(m, e);
    // ---- flips: triangles only; repeat passes until none improves ----
    for (int pass = 0; pass < 8; ++pass) {
      half.clear();
      for (std::size_t e = 0; e < m.solid.size(); ++e) {
        if (m.solid.type[e] != ElemType::Tri3) continue;
        const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
        for (int k = 0; k < 3; ++k)
          half.push_back({key_of(v[k].v, v[(k + 1) % 3].v), static_cast<std::int32_t>(e), k});
      }
      std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return x.key != y.key ? x.key < y.key : x.elem < y.elem;
      });
      std::vector<std::uint8_t> touched(m.solid.size(), 0);
      std::size_t flips = 0;
      for (std::size_t h = 0; h + 1 < half.size(); ++h) {
        if (half[h].key != half[h + 1].key || (h > 0 && half[h - 1].key == half[h].key) ||
            (h + 2 < half.size() && half[h + 2].key == half[h].key))
          continue;  // a boundary edge, or (never in a valid mesh) an edge of 3+ triangles
        const std::int32_t e0 = half[h].elem, e1 = half[h + 1].elem;
        const int k0 = half[h].local, k1 = half[h + 1].local;
        if (angle[e0] >= good && angle[e1] >= good) continue;
        if (std::binary_search(interface_edge.begin(), interface_edge.end(), half[h].key)) continue;
        if (touched[e0] || touched[e1]) continue;
        VertexId* v0 = m.solid.node.data() + m.solid.offset[e0];
        VertexId* v1 = m.solid.node.data() + m.solid.offset[e1];
        // Triangle 0 = (a, b, c) with edge a-b at k0; triangle 1 = (b, a, d).
        const std::int32_t a = v0[k0].v, b = v0[(k0 + 1) % 3].v, c = v0[(k0 + 2) % 3].v;
        const std::int32_t d = v1[(k1 + 2) % 3].v;
        if (v1[k1].v != b || v1[(k1 + 1) % 3].v != a) continue;  // not opposite orientation
        const P2 &pa = m.points[a], &pb = m.points[b], &pc = m.points[c], &pd = m.points[d];
        const double before = std::min(tri_min_angle(pa, pb, pc), tri_min_angle(pb, pa, pd));
        const double after = std::min(tri_min_angle(pc, pa, pd), tri_min_angle(pd, pb, pc));
        if (after <= before + 1e-9) continue;
        // New triangles (c, a, d) and (d, b, c): both positive since after > before >= -1.
        v0[0] = VertexId{c}, v0[1] = VertexId{a}, v0[2] = VertexId{d};
        v1[0] = VertexId{d}, v1[1] = VertexId{b}, v1[2] = VertexId{c};
        touched[e0] = touched[e1] = 1;
        angle[e0] = tri_min_angle(pc, pa, pd);
        angle[e1] = tri_min_angle(pd, pb, pc);
        ++flips;
      }
      st.flips += flips;
      if (flips == 0) break;
    }

    // ---- guarded smoothing on the smallest angle ----
    std::vector<std::vector<std::int32_t>> incident(n_nodes), neighbours(n_nodes), curve_neighbours(n_nodes);
    for (std::size_t e = 0; e < m.interface.size(); ++e) {
      const VertexId* v = m.interface.nodes(ElemId{static_cast<std::int32_t>(e)});
      curve_neighbours[v[0].v].push_back(v[1].v);
      curve_neighbours[v[1].v].push_back(v[0].v);
    }
    for (std::size_t e = 0; e < m.solid.size(); ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = m.solid.n_nodes_of(id);
      const VertexId* v = m.solid.nodes(id);
      for (int k = 0; k < n; ++k) {
        incident[v[k].v].push_back(static_cast<std::int32_t>(e));
        neighbours[v[k].v].push_back(v[(k + 1) % n].v);
        neighbours[v[k].v].push_back(v[(k + n - 1) % n].v);
      }
    }
    for (std::size_t v = 0; v < n_nodes; ++v) {
      const bool sliding = locked[v] == 2 && slide;
      if ((locked[v] && !sliding) || incident[v].empty()) continue;
      auto& nb = sliding ? curve_neighbours[v] : neighbours[v];
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
      if (nb.empty()) continue;
      P2 target = P2::Zero();
      for (std::int32_t w : nb) target += m.points[w];
      target /= static_cast<double>(nb.size());
      auto local_min = [&] {
        double q = 180.0;
        for (std::int32_t e : incident[v]) q = std::min(q, min_corner_angle_deg(m, e));
        return q;
      };
      const double old_q = local_min();
      const P2 saved = m.points[v];
      bool moved = false;
      for (double step : {1.0, 0.5, 0.25}) {
        m.points[v] = saved + step * (target - saved);
        if (sliding) m.points[v] = slide(static_cast<std::int32_t>(v), m.points[v]);
        if (m.points[v] == saved) break;
        if (local_min() > old_q + 1e-12) {
          moved = true;
          break;
        }
      }
      if (moved) {
        ++st.moves;
      } else {
        m.points[v] = saved;
      }
    }
  }
  st.min_angle_after = mesh_min();
  return st;
}

}  // namespace febemesh::dim2
