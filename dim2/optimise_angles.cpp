#include "dim2/optimise_angles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "core/huge_pages.hpp"
#include "core/incidence_csr.hpp"
#include "core/mesh_topology.hpp"
#include "core/parallel_ranges.hpp"
#include "core/partitioned_sweep.hpp"

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

/// How bad the worst corner of the polygon with nodes ev (n corners, CCW) is, without atan2:
/// triangles their largest corner cotangent, quads their largest |cotangent| (q falls as it
/// rises, for each kind); +inf when a corner is reflex or inverted or the quotient is not finite
/// (then only q itself tells). With n a template parameter (3, 4) the indices need no division.
template <int N = 0> double polygon_badness(const P2* points, const VertexId* ev, int n_runtime = N) {
  const int n = N > 0 ? N : n_runtime;
  constexpr double inf = std::numeric_limits<double>::infinity();
  double worst = -inf;
  for (int k = 0; k < n; ++k) {
    const P2 &prev = points[ev[(k + n - 1) % n].v], &cur = points[ev[k].v], &next = points[ev[(k + 1) % n].v];
    const P2 a = prev - cur, b = next - cur;
    const double cr = b[0] * a[1] - b[1] * a[0];
    if (!(cr > 0)) return inf;
    const double c = a.dot(b) / cr;
    if (!std::isfinite(c)) return inf;
    worst = std::max(worst, n == 3 ? c : std::abs(c));
  }
  return worst;
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

  // Node -> incident elements (CSR, on threads; nothing beside the lists: this stage holds the
  // 2D run's memory peak).
  std::vector<std::int32_t> first, incident;
  incidence_csr(
      n_nodes, n_elems,
      [&](std::size_t e, auto&& f) {
        const ElemId id{static_cast<std::int32_t>(e)};
        for (int k = 0; k < m.solid.n_nodes_of(id); ++k) f(m.solid.nodes(id)[k].v);
      },
      opt.n_threads, first, incident);
  // Edge neighbours of a node from its incident elements (append_polygon_neighbours), gathered
  // when the node is searched from: the connectivity does not change here, and most nodes are
  // above the target and never searched (flange level 9: the lists of all nodes up front were
  // 80M instructions and 4 bytes per node at this stage's memory peak).

  // Triangles measured against their own aim (q x target / triangle_target); 1 exactly when
  // there is none, so that one-kind meshes see angle_quality itself.
  const double triangle_scale = opt.triangle_target > 0 ? opt.target / opt.triangle_target : 1.0;
  auto scaled_quality = [&](std::size_t e) {
    const double q = angle_quality(m, e);
    return m.solid.type[e] == ElemType::Tri3 && q > 0 ? q * triangle_scale : q;
  };

  // The BE chord neighbours of each interface node, for the chord bound.
  const InterfaceNeighbours chord_nbr = opt.curve_distance ? interface_neighbours(m) : InterfaceNeighbours();
  // How far v's chords stray from the curve with v at p (their midpoints' distance).
  auto chord_deviation = [&](std::size_t v, const P2& p) {
    double d = 0.0;
    for (const std::int32_t u : chord_nbr.of(v)) d = std::max(d, opt.curve_distance(0.5 * (p + m.points[u])));
    return d;
  };

  // Worst q around v, or any value <= floor once it is known to be <= floor (the caller only
  // asks whether it beats floor).
  auto local_worst = [&](std::size_t v, double floor) {
    double q = 1e300;
    for (std::int32_t k = first[v]; k < first[v + 1] && q > floor; ++k) q = std::min(q, scaled_quality(incident[k]));
    return q;
  };
  // The q of every element, refreshed when one of its nodes moves: most nodes are already
  // above the target and are skipped on these cached values (the same numbers). An element
  // clearly above the target (clearly_above: no atan2) holds NaN until a node of it moves: it
  // cannot be the worst of a node below the target, nor of the mesh while one is below.
  std::vector<double> q_elem;
  reserve_huge(q_elem, n_elems, opt.n_threads);
  q_elem.resize(n_elems);
  // Corner angles that keep q above target + a margin (1e-3 deg): triangles at least
  // tri_deg, quad corners within [quad_deg, 180 - quad_deg]; their cotangents' bounds.
  const double tri_deg = (triangle_bar_deg * opt.target / triangle_scale) + 1e-3;
  const double quad_deg = quad_bar_deg * opt.target + 1e-3;
  const double tri_cot = tri_deg < 90.0 ? 1.0 / std::tan(tri_deg * M_PI / 180.0) : -1e300;
  const double quad_cot = quad_deg < 90.0 ? 1.0 / std::tan(quad_deg * M_PI / 180.0) : -1e300;
  // How bad an element's worst corner is (polygon_badness).
  constexpr double inf = std::numeric_limits<double>::infinity();
  auto badness = [&](std::size_t e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const int n = m.solid.n_nodes_of(id);
    const VertexId* ev = m.solid.nodes(id);
    if (n == 3) return polygon_badness<3>(m.points.data(), ev);
    if (n == 4) return polygon_badness<4>(m.points.data(), ev);
    return polygon_badness(m.points.data(), ev, n);
  };
  auto clearly_above = [&](std::size_t e) {
    return badness(e) < (m.solid.n_nodes_of(ElemId{static_cast<std::int32_t>(e)}) == 3 ? tri_cot : quad_cot);
  };
  for_each_range(n_elems, opt.n_threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t e = begin; e < end; ++e) q_elem[e] = clearly_above(e) ? std::nan("") : scaled_quality(e);
  });
  // The mesh's worst q: the measured elements' when one is at or below the target (the others
  // are above it). Else, per kind, it is held by an element within rounding (1e-9 of 1 + b^2)
  // of the kind's largest badness; only those (and the measured ones) are measured.
  // (On threads: maxima and minima, exact in any order.)
  auto mesh_worst = [&] {
    const auto is_tri = [&](std::size_t e) { return m.solid.n_nodes_of(ElemId{static_cast<std::int32_t>(e)}) == 3; };
    double q = std::min(1e300, range_min(n_elems, opt.n_threads, [&](std::size_t e) {
                                  return std::isnan(q_elem[e]) ? inf : q_elem[e];
                                }));
    if (q <= opt.target || n_elems == 0) return n_elems ? q : 0.0;
    // Each kind's largest finite badness, and per block of elements its own (and whether one
    // has none finite), in one pass; then only the blocks that can hold an element to measure
    // are read again. (Two passes for the two kinds and a third over all elements for the
    // measured ones were 38 ms at flange 1e6 on one thread, 22 on two.)
    constexpr std::size_t block = 4096;
    struct BlockTop {
      double top[2] = {-inf, -inf};  // triangles, quads
      bool unbounded = false;        // an element without a finite badness (always measured)
    };
    std::vector<BlockTop> blocks((n_elems + block - 1) / block);
    for_each_range(blocks.size(), opt.n_threads, [&](std::size_t b0, std::size_t b1) {
      for (std::size_t k = b0; k < b1; ++k)
        for (std::size_t e = k * block; e < std::min(n_elems, (k + 1) * block); ++e) {
          if (!std::isnan(q_elem[e])) continue;
          const double b = badness(e);
          if (!std::isfinite(b)) blocks[k].unbounded = true;
          else blocks[k].top[is_tri(e) ? 0 : 1] = std::max(blocks[k].top[is_tri(e) ? 0 : 1], b);
        }
    });
    double top[2] = {-inf, -inf};
    for (const BlockTop& t : blocks)
      for (const int kind : {0, 1}) top[kind] = std::max(top[kind], t.top[kind]);
    const auto near_top = [&](double b, int kind) { return top[kind] - b <= 1e-9 * (1.0 + top[kind] * top[kind]); };
    std::vector<std::size_t> read;  // an element within rounding of its kind's top lies in one of these
    for (std::size_t k = 0; k < blocks.size(); ++k)
      if (blocks[k].unbounded || near_top(blocks[k].top[0], 0) || near_top(blocks[k].top[1], 1)) read.push_back(k);
    return std::min(q, range_min(read.size(), opt.n_threads, [&](std::size_t i) {
                      double worst = inf;
                      for (std::size_t e = read[i] * block; e < std::min(n_elems, (read[i] + 1) * block); ++e) {
                        if (!std::isnan(q_elem[e])) continue;
                        const double b = badness(e);
                        if (!std::isfinite(b) || near_top(b, is_tri(e) ? 0 : 1)) worst = std::min(worst, scaled_quality(e));
                      }
                      return worst;
                    }));
  };
  if (opt.measure_worst) st.worst_before = mesh_worst();
  // The worst cached q around v; at least the target when all of v's elements are clearly
  // above it (then v is skipped, as with their exact q).
  auto cached_worst = [&](std::size_t v) {
    double q = 1e300;
    for (std::int32_t k = first[v]; k < first[v + 1]; ++k)
      if (!std::isnan(q_elem[incident[k]])) q = std::min(q, q_elem[incident[k]]);
    return q;
  };
  // local_worst with node v at p (the node is put back afterwards).
  auto worst_at = [&](std::size_t v, const P2& p, double floor) {
    const P2 keep = m.points[v];
    m.points[v] = p;
    const double q = local_worst(v, floor);
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
  // settled[v]: the search from v found no better place and no node of v's elements has moved
  // since; it would search the same numbers again and is skipped.
  std::vector<std::uint8_t> settled(n_nodes, 0);
  // The sweeps in slabs on threads (core/partitioned_sweep.hpp): a search from v reads v's
  // elements and their nodes, and writes v, its elements' q and (marks) their nodes' settled.
  struct alignas(64) Worker {
    std::vector<std::int32_t> nbr;
    std::vector<std::uint8_t> listed;  ///< append_polygon_neighbours' marks
    std::size_t moves = 0;
  };
  const auto lock_of = [&](std::size_t v) -> std::uint8_t { return v < locked.size() ? locked[v] : 0; };
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, default_sweep_parts, opt.n_threads);
  const PartitionedSweep sweep(
      part, default_sweep_parts, separators(part, m.solid, opt.n_threads),
      [&](std::int32_t v) {
        const std::uint8_t lock = lock_of(static_cast<std::size_t>(v));
        return first[v] != first[v + 1] && lock != 1 && !(lock == 2 && !slide);
      },
      opt.n_threads);
  std::vector<Worker> workers(static_cast<std::size_t>(sweep.n_threads()));
  for (Worker& w : workers) w.listed.assign(n_nodes, 0);
  for (int round = 0; round < opt.rounds; ++round) {
    sweep.run([&](std::int32_t vi, int thread) {
      Worker& my = workers[static_cast<std::size_t>(thread)];
      const auto v = static_cast<std::size_t>(vi);
      if (settled[v]) return;
      const std::uint8_t lock = lock_of(v);
      double best_q = cached_worst(v);
      if (best_q >= opt.target) {
        // The same until a node of its elements moves (their q are all it read): skipped till
        // then, as a search that found nothing (each round read every node's elements: 25 ms a
        // round, most of this stage, flange at 5.4 M triangles).
        settled[v] = 1;
        return;
      }
      const P2 start = m.points[v];
      // A candidate as the node would really sit there (on the curve for sliding nodes).
      auto place = [&](const P2& p) { return lock == 2 ? slide(static_cast<std::int32_t>(v), p) : p; };
      const bool bound_chords = lock == 2 && !chord_nbr.first.empty();
      const double chord_limit = bound_chords ? chord_deviation(v, start) : 0.0;
      std::vector<std::int32_t>& nbr = my.nbr;
      nbr.clear();
      append_polygon_neighbours(m.solid, static_cast<std::int32_t>(v),
                                std::span<const std::int32_t>(incident.data() + first[v], incident.data() + first[v + 1]),
                                nbr, my.listed);
      P2 best = start, centroid = P2::Zero();
      double h = 0.0;
      for (const std::int32_t w : nbr) {
        centroid += m.points[w];
        h += (m.points[w] - start).norm();
      }
      const double n_nbr = static_cast<double>(nbr.size());
      centroid /= n_nbr;
      h /= n_nbr;
      auto consider = [&](const P2& target) {
        const P2 p = place(target);
        if (p == best) return false;
        const double q = worst_at(v, p, best_q);
        if (q <= best_q) return false;
        if (bound_chords && chord_deviation(v, p) > chord_limit) return false;
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
        for (std::int32_t k = first[v]; k < first[v + 1]; ++k) {
          q_elem[incident[k]] = scaled_quality(incident[k]);
          const ElemId id{incident[k]};
          const VertexId* ev = m.solid.nodes(id);
          for (int j = 0; j < m.solid.n_nodes_of(id); ++j) mark(settled[ev[j].v], 0);
        }
        ++my.moves;
      } else {
        settled[v] = 1;
      }
    }, [] {}, [&](std::int32_t v) { return settled[v] != 0; });
    std::size_t moved_this_round = 0;
    for (Worker& w : workers) moved_this_round += std::exchange(w.moves, 0);
    st.moves += moved_this_round;
    if (moved_this_round == 0) break;
  }
  if (opt.measure_worst) st.worst_after = mesh_worst();
  return st;
}

}  // namespace febemesh::dim2
