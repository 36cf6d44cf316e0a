#include "dim2/optimise_angles.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace febemesh::dim2 {
namespace {

using P2 = Point<2>;

constexpr double triangle_bar_deg = 20.0;
constexpr double quad_bar_deg = 30.0;

/// q of the polygon pts (CCW) with n = 3 or 4 corners; -1 when a corner is reflex or inverted.
double polygon_quality(const P2* pts, int n) {
  double worst = 180.0;
  for (int k = 0; k < n; ++k) {
    const P2 a = pts[(k + n - 1) % n] - pts[k], b = pts[(k + 1) % n] - pts[k];
    const double cr = b[0] * a[1] - b[1] * a[0];  // > 0 for a convex CCW corner
    if (cr <= 0) return -1.0;
    const double ang = std::atan2(cr, a.dot(b)) * 180.0 / M_PI;
    worst = std::min(worst, n == 3 ? ang : std::min(ang, 180.0 - ang));
  }
  return worst / (n == 3 ? triangle_bar_deg : quad_bar_deg);
}

}  // namespace

double angle_quality(const Mesh<2>& m, std::size_t e) {
  const ElemId id{static_cast<std::int32_t>(e)};
  const int n = m.solid.n_nodes_of(id);
  std::array<P2, 4> p;
  for (int k = 0; k < n; ++k) p[k] = m.points[m.solid.nodes(id)[k].v];
  return polygon_quality(p.data(), n);
}

AngleOptimiseStats optimise_angles(Mesh<2>& m, const std::vector<std::uint8_t>& locked,
                                   const AngleOptimiseOptions& opt, const SlideFn& slide) {
  AngleOptimiseStats st;
  const std::size_t n_nodes = m.points.size(), n_elems = m.solid.size();
  auto mesh_worst = [&] {
    double q = 1e300;
    for (std::size_t e = 0; e < n_elems; ++e) q = std::min(q, angle_quality(m, e));
    return n_elems ? q : 0.0;
  };
  st.worst_before = mesh_worst();

  // Node -> incident elements (CSR) and node -> edge neighbours (CSR, sorted, unique).
  std::vector<std::int32_t> first(n_nodes + 1, 0);
  for (std::size_t e = 0; e < n_elems; ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    for (int k = 0; k < m.solid.n_nodes_of(id); ++k) ++first[m.solid.nodes(id)[k].v + 1];
  }
  for (std::size_t v = 0; v < n_nodes; ++v) first[v + 1] += first[v];
  std::vector<std::int32_t> incident(first.back()), fill(first.begin(), first.end() - 1);
  std::vector<std::int32_t> nbr_first(n_nodes + 1, 0), nbr;
  {
    std::vector<std::array<std::int32_t, 2>> pairs;
    for (std::size_t e = 0; e < n_elems; ++e) {
      const ElemId id{static_cast<std::int32_t>(e)};
      const int n = m.solid.n_nodes_of(id);
      const VertexId* v = m.solid.nodes(id);
      for (int k = 0; k < n; ++k) {
        incident[fill[v[k].v]++] = static_cast<std::int32_t>(e);
        pairs.push_back({v[k].v, v[(k + 1) % n].v});
        pairs.push_back({v[(k + 1) % n].v, v[k].v});
      }
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    nbr.reserve(pairs.size());
    for (const auto& pr : pairs) {
      ++nbr_first[pr[0] + 1];
      nbr.push_back(pr[1]);
    }
    for (std::size_t v = 0; v < n_nodes; ++v) nbr_first[v + 1] += nbr_first[v];
  }

  auto local_worst = [&](std::size_t v) {
    double q = 1e300;
    for (std::int32_t k = first[v]; k < first[v + 1]; ++k) q = std::min(q, angle_quality(m, incident[k]));
    return q;
  };
  // The q of every element, refreshed when one of its nodes moves: most nodes are already
  // above the target and are skipped on these cached values (the same numbers).
  std::vector<double> q_elem(n_elems);
  for (std::size_t e = 0; e < n_elems; ++e) q_elem[e] = angle_quality(m, e);
  auto cached_worst = [&](std::size_t v) {
    double q = 1e300;
    for (std::int32_t k = first[v]; k < first[v + 1]; ++k) q = std::min(q, q_elem[incident[k]]);
    return q;
  };
  // Worst q with node v at p (the node is put back afterwards).
  auto worst_at = [&](std::size_t v, const P2& p) {
    const P2 keep = m.points[v];
    m.points[v] = p;
    const double q = local_worst(v);
    m.points[v] = keep;
    return q;
  };

  static const std::array<std::array<double, 2>, 8> dirs = {{{1, 0},
                                                             {-1, 0},
                                                             {0, 1},
                                                             {0, -1},
                                                             {M_SQRT1_2, M_SQRT1_2},
                                                             {-M_SQRT1_2, M_SQRT1_2},
                                                             {M_SQRT1_2, -M_SQRT1_2},
                                                             {-M_SQRT1_2, -M_SQRT1_2}}};
  for (int round = 0; round < opt.rounds; ++round) {
    std::size_t moved_this_round = 0;
    for (std::size_t v = 0; v < n_nodes; ++v) {
      if (first[v] == first[v + 1]) continue;
      const std::uint8_t lock = v < locked.size() ? locked[v] : 0;
      if (lock == 1 || (lock == 2 && !slide)) continue;
      double best_q = cached_worst(v);
      if (best_q >= opt.target) continue;
      const P2 start = m.points[v];
      // A candidate as the node would really sit there (on the curve for sliding nodes).
      auto place = [&](const P2& p) { return lock == 2 ? slide(static_cast<std::int32_t>(v), p) : p; };
      P2 best = start, centroid = P2::Zero();
      double h = 0.0;
      for (std::int32_t k = nbr_first[v]; k < nbr_first[v + 1]; ++k) {
        centroid += m.points[nbr[k]];
        h += (m.points[nbr[k]] - start).norm();
      }
      const double n_nbr = nbr_first[v + 1] - nbr_first[v];
      centroid /= n_nbr;
      h /= n_nbr;
      auto consider = [&](const P2& target) {
        const P2 p = place(target);
        if (p == best) return false;
        const double q = worst_at(v, p);
        if (q <= best_q) return false;
        best_q = q;
        best = p;
        return true;
      };
      for (double f : {1.0, 0.5, 0.25}) consider(start + f * (centroid - start));
      // Pattern search around the best so far, halving the step when no direction helps.
      for (double s = 0.2 * h; s > 0.005 * h;) {
        bool improved = false;
        const P2 centre = best;
        for (const auto& d : dirs) improved |= consider(centre + s * P2(d[0], d[1]));
        if (!improved) s *= 0.5;
        if (best_q >= opt.target) break;
      }
      if (best != start) {
        m.points[v] = best;  // (the caller recomputes where sliding nodes lie on the curve)
        for (std::int32_t k = first[v]; k < first[v + 1]; ++k) q_elem[incident[k]] = angle_quality(m, incident[k]);
        ++st.moves;
        ++moved_this_round;
      }
    }
    if (moved_this_round == 0) break;
  }
  st.worst_after = mesh_worst();
  return st;
}

}  // namespace febemesh::dim2
