// Node graphs in CSR form; the guard re-evaluates only the elements incident to the moved node.

#include "core/smooth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "core/error.hpp"
#include "core/guard_order.hpp"
#include "core/huge_pages.hpp"
#include "core/incidence_csr.hpp"
#include "core/mesh_topology.hpp"
#include "core/ordered_sweep.hpp"
#include "core/parallel_ranges.hpp"
#include "core/partitioned_sweep.hpp"
#include "core/quality.hpp"
#include "core/sort_short.hpp"

namespace febemesh {

namespace {

/// Compressed adjacency lists: the neighbours of node v are item[start[v] .. start[v+1]).
struct Csr {
  std::vector<std::int32_t> start, item;
  std::span<const std::int32_t> of(std::int32_t v) const {
    return {item.data() + start[v], static_cast<std::size_t>(start[v + 1] - start[v])};
  }
};

/// Node -> the elements that use it, in increasing order (once per use).
Csr incident_elements(std::size_t n, const Elements& els, int n_threads = 1) {
  Csr g;
  incidence_csr(
      n, els.size(),
      [&](std::size_t e, auto&& f) {
        const ElemId id{static_cast<std::int32_t>(e)};
        for (int i = 0; i < els.n_nodes_of(id); ++i) f(els.nodes(id)[i].v);
      },
      n_threads, g.start, g.item);
  return g;
}

/// Node -> its distinct edge neighbours in `els`, ascending: the lists the pairs of
/// unique_edges(els) taken both ways gave (an edge (v, v) of a degenerate element lists v
/// twice there, and here). Built node by node from `incident` (incident_elements(n, els)), each
/// list by marks (seen[w] == v) and then sorted, counted first so that the array has its exact
/// size: the list of every edge use both ways, 48 B a tetrahedron, was the 3D pipeline's heap
/// peak (sphere966 L5, heaptrack), and sorting each node's ~70 uses 247 M of the CLI's 8.2 G
/// instructions (callgrind). With `once`, sets once[v] = 1 for the nodes of the edges that one
/// element uses: for triangles and quads, whose facets are their edges, the nodes of
/// boundary_facets(els).
/// Node ranges on n_threads threads (the same lists for every count).
Csr edge_neighbours(std::size_t n, const Elements& els, const Csr& incident, std::vector<std::uint8_t>* once = nullptr,
                    int n_threads = 1) {
  Csr g;
  reserve_huge(g.start, n + 1, n_threads);
  g.start.assign(n + 1, 0);
  // Calls visit(w) for every edge (v, w) of v's elements, once per edge use ((v, v): twice).
  auto each_use = [&](std::int32_t v, auto&& visit) {
    const auto elems = incident.of(v);
    for (std::size_t k = 0; k < elems.size(); ++k) {
      if (k > 0 && elems[k] == elems[k - 1]) continue;  // an element using v twice: its edges once
      const ElemId id{elems[k]};
      const VertexId* nodes = els.nodes(id);
      const ElemType t = els.type[static_cast<std::size_t>(elems[k])];
      const auto edge = [&](std::int32_t a, std::int32_t b) {
        if (a == v) visit(b);
        if (b == v) visit(a);
      };
      if (t == ElemType::Tri3 || t == ElemType::Quad4) {
        // Edges (i, i+1): each place of v gives its two polygon neighbours (the uses the edge
        // loop below gives, in another order, which the lists' sort and marks do not see).
        const int m = t == ElemType::Tri3 ? 3 : 4;
        for (int i = 0; i < m; ++i)
          if (nodes[i].v == v) visit(nodes[i + 1 == m ? 0 : i + 1].v), visit(nodes[i == 0 ? m - 1 : i - 1].v);
      } else if (t == ElemType::Line2) {
        edge(nodes[0].v, nodes[1].v);
      } else if (t == ElemType::Tet4) {  // every pair: v's are those of v's places, with each other node
        for (int i = 0; i < 4; ++i)
          if (nodes[i].v == v)
            for (int j = 0; j < 4; ++j)
              if (j != i) visit(nodes[j].v);
      } else {
        for (int e = 0; e < n_edges(t); ++e) {
          const auto [a, b] = edge_local_nodes(t, e);
          edge(nodes[a].v, nodes[b].v);
        }
      }
    }
  };
  // Calls emit(w) once for each distinct w of v's uses, marking them in `seen` and counting
  // uses[w] when `once`; true when v itself is among them.
  const auto distinct_uses = [&](std::int32_t self, std::vector<std::int32_t>& seen, std::vector<std::int32_t>& uses,
                                 auto&& emit) {
    bool has_self = false;
    each_use(self, [&](std::int32_t w) {
      if (once) ++uses[w];
      if (seen[w] == self) return;
      seen[w] = self;
      has_self = has_self || w == self;
      emit(w);
    });
    return has_self;
  };
  // Sorts v's distinct values [lo, hi), flags `once` from the counts uses[w] of v's uses of w
  // (then cleared), and with has_self lists v a second time, in the slot at hi.
  const auto finish = [&](std::int32_t self, auto lo, auto hi, bool has_self, std::vector<std::int32_t>& uses) {
    sort_short(lo, hi);
    if (once) {
      // A value of a single use flags v (v itself: one use lists it twice).
      for (auto i = lo; i != hi; ++i)
        if (uses[*i] == (*i == self ? 2 : 1)) (*once)[static_cast<std::size_t>(self)] = 1;
      for (auto i = lo; i != hi; ++i) uses[*i] = 0;
    }
    if (has_self) {  // v itself twice, as one value per run of the sorted uses gave it
      const auto at = std::lower_bound(lo, hi, self) + 1;
      std::copy_backward(at, hi, hi + 1);
      *at = self;
    }
  };
  // One thread, and elements whose uses list at most two neighbours each (triangles, quads,
  // lines): each list is written at its place as it is made, in room reserved for two a use
  // (room never written is never touched), without the counting pass (a third of this
  // function's instructions, flange level 9). The same lists as the counted fill below.
  const bool two_a_use = std::all_of(els.type.begin(), els.type.end(), [](ElemType t) {
    return t == ElemType::Tri3 || t == ElemType::Quad4 || t == ElemType::Line2;
  });
  if (n_threads <= 1 && two_a_use) {
    reserve_room(g.item, 2 * incident.item.size());
    std::vector<std::int32_t> seen(n, -1), uses;
    if (once) uses.assign(n, 0);
    for (std::size_t v = 0; v < n; ++v) {
      const auto self = static_cast<std::int32_t>(v);
      const auto first = static_cast<std::ptrdiff_t>(g.item.size());
      const bool has_self = distinct_uses(self, seen, uses, [&](std::int32_t w) { g.item.push_back(w); });
      if (has_self) g.item.push_back(self);  // the second slot (finish moves it into place)
      finish(self, g.item.begin() + first, g.item.end() - (has_self ? 1 : 0), has_self, uses);
      g.start[v + 1] = static_cast<std::int32_t>(g.item.size());
    }
    return g;
  }
  // Each thread's marks: seen[w] == v while v's list is made, uses[w] counts v's uses of w.
  // Node chunks go to the threads as they come free: a node's cost is its elements', and the
  // surface nodes come last.
  const std::size_t chunk = std::size_t(1) << 12;
  for_each_chunk_balanced(n, chunk, n_threads, [&](auto&& next) {
    std::vector<std::int32_t> seen(n, -1);
    for (std::size_t begin = 0, end = 0; next(begin, end);)
      for (std::size_t v = begin; v < end; ++v) {
        const auto self = static_cast<std::int32_t>(v);
        std::int32_t count = 0;
        each_use(self, [&](std::int32_t w) {
          if (seen[w] == self) return;
          seen[w] = self;
          count += w == self ? 2 : 1;  // v itself twice
        });
        g.start[v + 1] = count;
      }
  });
  for (std::size_t v = 0; v < n; ++v) g.start[v + 1] += g.start[v];
  reserve_huge(g.item, static_cast<std::size_t>(g.start[n]), n_threads);
  g.item.resize(static_cast<std::size_t>(g.start[n]));
  for_each_chunk_balanced(n, chunk, n_threads, [&](auto&& next) {
    std::vector<std::int32_t> seen(n, -1), uses;
    if (once) uses.assign(n, 0);
    for (std::size_t begin = 0, end = 0; next(begin, end);)
      for (std::size_t v = begin; v < end; ++v) {
        const auto self = static_cast<std::int32_t>(v);
        std::int32_t out = g.start[v];
        const bool has_self =
            distinct_uses(self, seen, uses, [&](std::int32_t w) { g.item[static_cast<std::size_t>(out++)] = w; });
        finish(self, g.item.begin() + g.start[v], g.item.begin() + out, has_self, uses);
      }
  });
  return g;
}

}  // namespace

template <int Dim> SmoothStats smooth(Mesh<Dim>& mesh, const SmoothOptions<Dim>& options) {
  const std::size_t n = mesh.points.size();
  MESH_ASSERT(options.fixed.empty() || options.fixed.size() == n, "fixed has " << options.fixed.size() << " entries");
  SmoothStats stats;

  // The boundary nodes: of triangles and quads, the edge neighbours' counts tell them (the
  // facet sort of boundary_facets was 14% of the 2D smoothing's instructions, flange level 9);
  // else, or when they slide along the boundary's own graph, the boundary facets.
  const bool polygons = !options.project && std::all_of(mesh.solid.type.begin(), mesh.solid.type.end(), [](ElemType t) {
    return t == ElemType::Tri3 || t == ElemType::Quad4;
  });
  std::vector<std::uint8_t> on_boundary(n, 0);
  const Csr incident = incident_elements(n, mesh.solid, options.n_threads);
  const bool known = options.boundary_fixed && !options.project && options.fixed.size() == n;
  // Triangles and quads swept by parts, every boundary node fixed (the 2D pipeline): a visit
  // gathers v's neighbours from its elements (append_polygon_neighbours), and most visits are
  // of the first sweep only (min_move settles them). The lists of every node up front were
  // most of the 2D smoothing stage (flange at 5.4 M triangles: 0.2-0.4 s of setup against
  // 0.14 s of sweeps on one thread) and 24 B a node.
  const bool gather = polygons && known && options.parts > 0;
  const Csr neighbours = gather ? Csr{} : edge_neighbours(n, mesh.solid, incident, polygons ? &on_boundary : nullptr, options.n_threads);
  Elements boundary;
  if (!polygons && !known) {
    for (const BoundaryFacet& b : boundary_facets(mesh.solid)) {
      // The boundary's own graph is needed only when boundary nodes slide.
      if (options.project) boundary.add(b.facet.type, b.facet.node.data(), b.facet.n);
      for (int i = 0; i < b.facet.n; ++i) on_boundary[b.facet.node[i].v] = 1;
    }
  }
  const Csr boundary_neighbours = options.project ? edge_neighbours(n, boundary, incident_elements(n, boundary)) : Csr{};

  auto element_state = [&](std::int32_t e) {
    const ElemType type = mesh.solid.type[e];
    if constexpr (Dim == 3) {
      if (type == ElemType::Tet4) {  // the same numbers without the 8-point copy
        const VertexId* v = mesh.solid.nodes(ElemId{e});
        const std::array<Point<3>, 4> p = {mesh.points[v[0].v], mesh.points[v[1].v], mesh.points[v[2].v],
                                           mesh.points[v[3].v]};
        const auto [jac, scaled] = jacobians<3>(type, std::span<const Point<3>>(p.data(), 4));
        return std::pair{jac > 0.0, scaled};
      }
    } else {
      // Likewise for triangles and quads, inline (jacobians' normalisations: 2/sqrt(3), 1).
      const VertexId* v = mesh.solid.nodes(ElemId{e});
      if (type == ElemType::Tri3) {
        const Point<2> p[3] = {mesh.points[v[0].v], mesh.points[v[1].v], mesh.points[v[2].v]};
        const auto [jac, scaled] = polygon_jacobians<3>(p, 2.0 / std::sqrt(3.0));
        return std::pair{jac > 0.0, scaled};
      }
      if (type == ElemType::Quad4) {
        const Point<2> p[4] = {mesh.points[v[0].v], mesh.points[v[1].v], mesh.points[v[2].v], mesh.points[v[3].v]};
        const auto [jac, scaled] = polygon_jacobians<4>(p, 1.0);
        return std::pair{jac > 0.0, scaled};
      }
    }
    const auto ep = element_points<Dim>(mesh.solid, ElemId{e}, mesh.points);
    const auto [jac, scaled] = jacobians<Dim>(type, ep.span());
    return std::pair{jac > 0.0, scaled};
  };
  // The state of every element, refreshed where a move is accepted: the guard compares against
  // it instead of re-evaluating the incident elements before each move (same values). Its two
  // parts in two arrays, 9 bytes an element: a pair<bool, double> (16) made this the 2D run's
  // heap peak (flange level 9, massif).
  std::vector<double> scaled;
  std::vector<std::uint8_t> valid;
  reserve_huge(scaled, mesh.solid.size(), options.n_threads);
  reserve_huge(valid, mesh.solid.size(), options.n_threads);
  scaled.resize(mesh.solid.size());
  valid.resize(mesh.solid.size());
  auto set_state = [&](std::int32_t e, const std::pair<bool, double>& st) {
    valid[static_cast<std::size_t>(e)] = st.first ? 1 : 0;
    scaled[static_cast<std::size_t>(e)] = st.second;
  };
  // The scaled Jacobians are those of the current points (before and after).
  auto min_quality = [&] {
    double q = std::numeric_limits<double>::infinity();
    for (const double sj : scaled) q = std::min(q, sj);
    return scaled.empty() ? 0.0 : q;
  };
  // Tetrahedra only: their states four at a time (tet_jacobians_n, the same numbers).
  const bool all_tets = Dim == 3 && std::all_of(mesh.solid.type.begin(), mesh.solid.type.end(),
                                                [](ElemType t) { return t == ElemType::Tet4; });
  // Without min_quality, valid[e] == 2 until e's state is first read (fill_states).
  const bool lazy = !options.min_quality;
  if (lazy) std::fill(valid.begin(), valid.end(), std::uint8_t{2});
  else for_each_range(mesh.solid.size(), options.n_threads, [&](std::size_t begin, std::size_t end) {
    if constexpr (Dim == 3) {
      if (all_tets) {
        constexpr std::size_t block = 256;
        std::vector<Point<3>> pts(4 * block);
        std::array<double, block> jac{}, sj{};
        for (std::size_t first = begin; first < end; first += block) {
          const std::size_t n_here = std::min(block, end - first);
          for (std::size_t i = 0; i < n_here; ++i) {
            const VertexId* v = mesh.solid.nodes(ElemId{static_cast<std::int32_t>(first + i)});
            for (int k = 0; k < 4; ++k) pts[4 * i + k] = mesh.points[v[k].v];
          }
          tet_jacobians_n(pts.data(), n_here, jac.data(), sj.data());
          for (std::size_t i = 0; i < n_here; ++i) set_state(static_cast<std::int32_t>(first + i), {jac[i] > 0.0, sj[i]});
        }
        return;
      }
    }
    for (std::size_t e = begin; e < end; ++e) set_state(static_cast<std::int32_t>(e), element_state(static_cast<std::int32_t>(e)));
  });
  if (!lazy) stats.min_quality_before = min_quality();
  // The states of v's elements that no visit has read yet (lazy): a visit of v writes only the
  // states of v's elements, so the sweeps' threads never evaluate the same one, and an element's
  // stored state is always that of the current points (an accepted move rewrites the states of
  // all the moved node's elements): the value the up-front pass would have left there.
  const auto fill_states = [&](std::span<const std::int32_t> elems) {
    for (const std::int32_t e : elems)
      if (valid[static_cast<std::size_t>(e)] == 2) set_state(e, element_state(e));
  };
  // settled[v]: 1 if v's target was where it stands, 2 if its move was rejected, and no node of
  // its elements has moved since; its target, its elements' states and the trial states would
  // be the same numbers, so the same outcome: it is skipped (and counted as before).
  std::vector<std::uint8_t> settled(n, 0);
  // The nodes that may move, swept in order; the visit of v reads and writes only the nodes and
  // states of v's elements, so on several threads v goes as soon as its lower neighbours are
  // done (core/ordered_sweep.hpp), or, with parts, as core/partitioned_sweep.hpp says.
  const auto movable = [&](std::size_t v) {
    if (!options.fixed.empty() && options.fixed[v]) return false;
    const bool slides = on_boundary[v] != 0;
    if (slides && !options.project) return false;
    const auto id = static_cast<std::int32_t>(v);
    return (gather || !(slides ? boundary_neighbours.of(id) : neighbours.of(id)).empty()) && !incident.of(id).empty();
  };
  std::optional<OrderedSweep> in_order;
  std::optional<PartitionedSweep> by_parts;
  if (options.parts > 0) {
    const std::vector<std::uint8_t> part = slab_parts<Dim>(mesh.points, options.parts, options.n_threads);
    by_parts.emplace(part, options.parts, separators(part, mesh.solid, options.n_threads),
                     [&](std::int32_t v) { return movable(static_cast<std::size_t>(v)); }, options.n_threads);
  } else {
    std::vector<std::int32_t> nodes;
    for (std::size_t v = 0; v < n; ++v)
      if (movable(v)) nodes.push_back(static_cast<std::int32_t>(v));
    // In triangles and tetrahedra every two nodes of an element share an edge: the edge
    // neighbours (sorted, distinct) are the nodes of v's elements, which the sweep's DAG needs.
    // Listing those from the elements again was 0.11 s of the 2-thread smoothing (sphere966 L6,
    // 1.5 M tetrahedra, ~96 uses a node sorted).
    const bool simplices = !gather && std::all_of(mesh.solid.type.begin(), mesh.solid.type.end(), [](ElemType t) {
      return t == ElemType::Tri3 || t == ElemType::Tet4;
    });
    in_order.emplace(std::move(nodes), n, options.n_threads, [&](std::int32_t v, auto&& visit) {
      if (simplices) {
        for (const std::int32_t w : neighbours.of(v)) visit(w);
        return;
      }
      for (const std::int32_t e : incident.of(v)) {
        const VertexId* ev = mesh.solid.nodes(ElemId{e});
        for (int j = 0; j < mesh.solid.n_nodes_of(ElemId{e}); ++j) visit(ev[j].v);
      }
    });
  }
  struct alignas(64) PerThread {
    std::vector<std::pair<bool, double>> after;
    std::vector<Point<Dim>> pts;       ///< the tetrahedra's points (all_tets)
    std::vector<double> jac, sj;       ///< their states (all_tets)
    std::vector<std::int32_t> nbrs;    ///< gathered neighbours (gather)
    std::vector<std::uint8_t> listed;  ///< their marks (gather)
    std::size_t accepted = 0, rejected = 0;
  };
  std::vector<PerThread> per_thread(static_cast<std::size_t>(by_parts ? by_parts->n_threads() : in_order->n_threads()));
  if (gather)
    for (PerThread& my : per_thread) my.listed.assign(n, 0);
  const auto visit = [&](std::int32_t v, int t) {
    PerThread& my = per_thread[static_cast<std::size_t>(t)];
    if (settled[v]) {
      my.rejected += settled[v] == 2;
      return;
    }
    const bool slides = on_boundary[v] != 0;
    const auto elems = incident.of(v);
    std::span<const std::int32_t> nbrs;
    if (gather) {
      my.nbrs.clear();
      append_polygon_neighbours(mesh.solid, v, elems, my.nbrs, my.listed);
      nbrs = my.nbrs;
      if (nbrs.empty()) {  // (no element with another node)
        settled[v] = 1;
        return;
      }
    } else {
      nbrs = slides ? boundary_neighbours.of(v) : neighbours.of(v);
    }
    Point<Dim> target = Point<Dim>::Zero();
    for (const auto w : nbrs) target += mesh.points[w];
    target /= static_cast<double>(nbrs.size());
    if (slides) target = options.project(target);
    if (target == mesh.points[v] || (options.min_move > 0 && within_rounding<Dim>(mesh.points, v, nbrs, target, options.min_move))) {
      settled[v] = 1;
      return;
    }

    double old_min = std::numeric_limits<double>::infinity();
    std::size_t worst = 0;
    if (lazy) fill_states(elems);
    for (std::size_t k = 0; k < elems.size(); ++k) {
      if (scaled[elems[k]] < old_min) worst = k;
      old_min = std::min(old_min, scaled[elems[k]]);
    }
    const Point<Dim> saved = mesh.points[v];
    mesh.points[v] = target;
    bool accept = true;
    std::vector<std::pair<bool, double>>& after = my.after;
    after.resize(elems.size());
    // Accepted iff no valid element inverts and every element stays >= old_min.
    const auto passes = [&](std::size_t k) { return (after[k].first || !valid[elems[k]]) && after[k].second >= old_min; };
    if (!all_tets) {
      // The first element that fails decides, the element that held old_min (likeliest to
      // drop) first.
      for (std::size_t j = 0; j < elems.size() && accept; ++j) {
        const std::size_t k = worst_first(j, worst);
        after[k] = element_state(elems[k]);
        accept = passes(k);
      }
    } else if constexpr (Dim == 3) {  // (all_tets is false in 2D)
      // The worst alone first (most rejections stop there), then all of them four at a time:
      // the same states, and the same verdict (every element must pass either way).
      after[worst] = element_state(elems[worst]);
      accept = passes(worst);
      if (accept && elems.size() > 1) {
        my.pts.resize(4 * elems.size());
        my.jac.resize(elems.size());
        my.sj.resize(elems.size());
        for (std::size_t k = 0; k < elems.size(); ++k) {
          const VertexId* ev = mesh.solid.nodes(ElemId{elems[k]});
          for (int i = 0; i < 4; ++i) my.pts[4 * k + i] = mesh.points[ev[i].v];
        }
        tet_jacobians_n(my.pts.data(), elems.size(), my.jac.data(), my.sj.data());
        for (std::size_t k = 0; k < elems.size() && accept; ++k) {
          after[k] = {my.jac[k] > 0.0, my.sj[k]};
          accept = passes(k);
        }
      }
    }
    if (accept) {
      ++my.accepted;
      for (std::size_t k = 0; k < elems.size(); ++k) {
        set_state(elems[k], after[k]);
        const ElemId id{elems[k]};
        const VertexId* ev = mesh.solid.nodes(id);
        for (int j = 0; j < mesh.solid.n_nodes_of(id); ++j) mark(settled[ev[j].v], 0);
      }
    } else {
      mesh.points[v] = saved;
      ++my.rejected;
      settled[v] = 2;
    }
  };
  for (int it = 0; it < options.n_iterations; ++it) {
    ++stats.iterations;
    if (by_parts)
      by_parts->run(visit);
    else
      in_order->run(visit);
  }
  if (options.at_rest) {
    options.at_rest->clear();
    if (gather) {  // settled's own storage (a copy was the 2D run's memory peak + 2 B/element)
      for (std::uint8_t& s : settled) s = s == 1 ? 1 : 0;
      *options.at_rest = std::move(settled);
    }
  }
  for (const PerThread& my : per_thread) {
    stats.moves_accepted += my.accepted;
    stats.moves_rejected += my.rejected;
  }
  if (!lazy) stats.min_quality_after = min_quality();
  return stats;
}

template SmoothStats smooth<2>(Mesh<2>&, const SmoothOptions<2>&);
template SmoothStats smooth<3>(Mesh<3>&, const SmoothOptions<3>&);

}  // namespace febemesh
