// Gmsh reference-element tables (Gmsh MElement sources: edges_*, faces_*), oriented outward.

#include "core/mesh_topology.hpp"

#include <algorithm>
#include <functional>
#include <limits>

#include "core/error.hpp"
#include "core/parallel_ranges.hpp"

namespace febemesh {

namespace {

constexpr int line_facets[2][1] = {{0}, {1}};
constexpr int tri_facets[3][2] = {{0, 1}, {1, 2}, {2, 0}};
constexpr int quad_facets[4][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
constexpr int tet_facets[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {3, 1, 2}};
constexpr int hex_facets[6][4] = {{0, 3, 2, 1}, {0, 1, 5, 4}, {0, 4, 7, 3},
                                  {1, 2, 6, 5}, {2, 3, 7, 6}, {4, 5, 6, 7}};
// Prism and pyramid mix triangles and quads; -1 pads the triangles.
constexpr int prism_facets[5][4] = {{0, 2, 1, -1}, {3, 4, 5, -1}, {0, 1, 4, 3}, {0, 3, 5, 2}, {1, 2, 5, 4}};
constexpr int pyramid_facets[5][4] = {{0, 1, 4, -1}, {3, 0, 4, -1}, {1, 2, 4, -1}, {2, 3, 4, -1}, {0, 3, 2, 1}};

constexpr int line_edges[1][2] = {{0, 1}};
constexpr int tri_edges[3][2] = {{0, 1}, {1, 2}, {2, 0}};
constexpr int quad_edges[4][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
constexpr int tet_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
constexpr int hex_edges[12][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 5}, {2, 3},
                                  {2, 6}, {3, 7}, {4, 5}, {4, 7}, {5, 6}, {6, 7}};
constexpr int prism_edges[9][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4}, {2, 5}, {3, 4}, {3, 5}, {4, 5}};
constexpr int pyramid_edges[8][2] = {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 4}, {2, 3}, {2, 4}, {3, 4}};

template <std::size_t N, std::size_t M> std::span<const int> row(const int (&table)[N][M], int f) {
  MESH_ASSERT(f >= 0 && static_cast<std::size_t>(f) < N, "facet " << f << " of " << N);
  const int* r = table[f];
  std::size_t n = M;
  while (n > 0 && r[n - 1] < 0) --n;
  return {r, n};
}

}  // namespace

int n_facets(ElemType t) {
  switch (t) {
    case ElemType::Line2: return 2;
    case ElemType::Tri3: return 3;
    case ElemType::Quad4: return 4;
    case ElemType::Tet4: return 4;
    case ElemType::Hex8: return 6;
    case ElemType::Prism6: return 5;
    case ElemType::Pyramid5: return 5;
  }
  return 0;
}

int n_edges(ElemType t) {
  switch (t) {
    case ElemType::Line2: return 1;
    case ElemType::Tri3: return 3;
    case ElemType::Quad4: return 4;
    case ElemType::Tet4: return 6;
    case ElemType::Hex8: return 12;
    case ElemType::Prism6: return 9;
    case ElemType::Pyramid5: return 8;
  }
  return 0;
}

std::span<const int> facet_local_nodes(ElemType t, int f) {
  switch (t) {
    case ElemType::Line2: return row(line_facets, f);
    case ElemType::Tri3: return row(tri_facets, f);
    case ElemType::Quad4: return row(quad_facets, f);
    case ElemType::Tet4: return row(tet_facets, f);
    case ElemType::Hex8: return row(hex_facets, f);
    case ElemType::Prism6: return row(prism_facets, f);
    case ElemType::Pyramid5: return row(pyramid_facets, f);
  }
  return {};
}

ElemType facet_type(ElemType t, int f) {
  switch (facet_local_nodes(t, f).size()) {
    case 2: return ElemType::Line2;
    case 3: return ElemType::Tri3;
    default: return ElemType::Quad4;
  }
}

std::array<int, 2> edge_local_nodes(ElemType t, int e) {
  auto get = [e](const auto& table) {
    MESH_ASSERT(e >= 0 && static_cast<std::size_t>(e) < std::size(table), "edge " << e);
    return std::array<int, 2>{table[e][0], table[e][1]};
  };
  switch (t) {
    case ElemType::Line2: return get(line_edges);
    case ElemType::Tri3: return get(tri_edges);
    case ElemType::Quad4: return get(quad_edges);
    case ElemType::Tet4: return get(tet_edges);
    case ElemType::Hex8: return get(hex_edges);
    case ElemType::Prism6: return get(prism_edges);
    case ElemType::Pyramid5: return get(pyramid_edges);
  }
  return {0, 0};
}

Facet facet_of(const Elements& els, ElemId e, int f) {
  const ElemType t = els.type[e.v];
  if (t == ElemType::Tet4) {  // the validator's hot path: the table without the row's trimming
    MESH_ASSERT(f >= 0 && f < 4, "facet " << f);
    const VertexId* nodes = els.nodes(e);
    return Facet{ElemType::Tri3, 3, {nodes[tet_facets[f][0]], nodes[tet_facets[f][1]], nodes[tet_facets[f][2]], VertexId{}}};
  }
  const auto local = facet_local_nodes(t, f);
  const VertexId* nodes = els.nodes(e);
  Facet out;
  out.type = facet_type(t, f);
  out.n = static_cast<int>(local.size());
  for (int i = 0; i < out.n; ++i) out.node[i] = nodes[local[i]];
  return out;
}

Facet as_facet(const Elements& els, ElemId e) {
  Facet out;
  out.type = els.type[e.v];
  out.n = els.n_nodes_of(e);
  MESH_ASSERT(out.n >= 2 && out.n <= 4, "element " << e.v << " is not a facet type");
  for (int i = 0; i < out.n; ++i) out.node[i] = els.nodes(e)[i];
  return out;
}

FacetKey key_of(const Facet& f) {
  FacetKey k;
  // Insertion sort of at most 4 ids (std::sort on a short prefix trips g++ 12's -Warray-bounds).
  for (int i = 0; i < f.n; ++i) {
    int j = i;
    for (; j > 0 && k.v[j - 1] > f.node[i].v; --j) k.v[j] = k.v[j - 1];
    k.v[j] = f.node[i].v;
  }
  return k;
}

int orientation_of(const Facet& f) {
  if (f.n == 2) return f.node[0].v < f.node[1].v ? 1 : -1;
  // Rotate the smallest node to the front; the cycle direction is then read off its neighbours.
  int m = 0;
  for (int i = 1; i < f.n; ++i)
    if (f.node[i].v < f.node[m].v) m = i;
  const int next = f.node[(m + 1) % f.n].v;
  const int prev = f.node[(m + f.n - 1) % f.n].v;
  return next < prev ? 1 : -1;
}

namespace {

/// Calls visit(use) for every facet use in generation order: (element, local facet) increasing.
template <class Visit> void each_facet_use(const Elements& els, Visit&& visit) {
  for (std::size_t e = 0; e < els.size(); ++e) {
    const ElemId id{static_cast<std::int32_t>(e)};
    const ElemType t = els.type[e];
    if (t == ElemType::Tri3 || t == ElemType::Quad4) {
      // Facets (k, k+1): key and orientation read off the nodes, without the tables' calls
      // (facet_uses at flange level 9: 228M -> 120M instructions).
      const int n = t == ElemType::Tri3 ? 3 : 4;
      const VertexId* v = els.nodes(id);
      for (int f = 0; f < n; ++f) {
        const std::int32_t a = v[f].v, b = v[f + 1 == n ? 0 : f + 1].v;
        FacetUse u{FacetKey{}, id, static_cast<std::int8_t>(f), static_cast<std::int8_t>(a < b ? 1 : -1)};
        u.key.v[0] = std::min(a, b), u.key.v[1] = std::max(a, b);
        visit(u);
      }
      continue;
    }
    for (int f = 0; f < n_facets(t); ++f) {
      const Facet fc = facet_of(els, id, f);
      visit(FacetUse{key_of(fc), id, static_cast<std::int8_t>(f), static_cast<std::int8_t>(orientation_of(fc))});
    }
  }
}

/// Every facet use in generation order.
std::vector<FacetUse> unsorted_uses(const Elements& els) {
  std::vector<FacetUse> uses;
  std::size_t total = 0;
  for (std::size_t e = 0; e < els.size(); ++e) total += static_cast<std::size_t>(n_facets(els.type[e]));
  uses.reserve(total);
  each_facet_use(els, [&](const FacetUse& u) { uses.push_back(u); });
  return uses;
}

/// Calls visit(smallest node) for every facet use (in no particular order within an element):
/// facet_uses' bucket counts without building the keys.
template <class Visit> void each_facet_smallest(const Elements& els, Visit&& visit) {
  for (std::size_t e = 0; e < els.size(); ++e) {
    const ElemType t = els.type[e];
    const VertexId* v = els.nodes(ElemId{static_cast<std::int32_t>(e)});
    if (t == ElemType::Tet4) {  // the four facets are the four triples
      const std::int32_t a = v[0].v, b = v[1].v, c = v[2].v, d = v[3].v;
      visit(std::min({b, c, d})), visit(std::min({a, c, d})), visit(std::min({a, b, d})), visit(std::min({a, b, c}));
      continue;
    }
    for (int f = 0; f < n_facets(t); ++f) {
      std::int32_t m = std::numeric_limits<std::int32_t>::max();
      for (const int k : facet_local_nodes(t, f)) m = std::min(m, v[k].v);
      visit(m);
    }
  }
}

/// Stable sort of the short range [first, last) (a bucket: the uses or edges of one node).
template <class It, class Less> void sort_bucket(It first, It last, Less less) {
  if (last - first > 32) {
    std::stable_sort(first, last, less);
    return;
  }
  for (It i = first + (first != last); i < last; ++i)
    for (It j = i; j != first && less(*j, *(j - 1)); --j) std::iter_swap(j, j - 1);
}

}  // namespace

// Cost: the uses are generated in (element, local facet) order, so a stable counting sort by the
// smallest node followed by a stable sort of each node's few uses by the remaining key gives the
// (key, element, local) order in linear time (facet_uses_ref: one comparison sort, same order).
// The counting pass reads only the smallest nodes, and the uses go straight to their buckets:
// no unsorted copy (24 B a use, 96 B a tetrahedron, beside the sorted one at the heap peak).
std::vector<FacetUse> facet_uses(const Elements& els) {
  std::int64_t top = -1;  // any bound on the smallest ids will do: the largest node
  for (const VertexId v : els.node) top = std::max<std::int64_t>(top, v.v);
  // Ids are >= -1: bucket = smallest id + 1.
  const std::size_t n_buckets = static_cast<std::size_t>(top + 2);
  std::vector<std::size_t> start(n_buckets + 1, 0);
  each_facet_smallest(els, [&](std::int32_t m) { ++start[static_cast<std::size_t>(m + 1) + 1]; });
  for (std::size_t b = 0; b < n_buckets; ++b) start[b + 1] += start[b];
  std::vector<FacetUse> sorted(start[n_buckets]);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    each_facet_use(els, [&](const FacetUse& u) { sorted[fill[static_cast<std::size_t>(u.key.v[0] + 1)]++] = u; });
  }
  for (std::size_t b = 0; b + 1 < start.size(); ++b)
    sort_bucket(sorted.begin() + static_cast<std::ptrdiff_t>(start[b]),
                sorted.begin() + static_cast<std::ptrdiff_t>(start[b + 1]), [](const FacetUse& x, const FacetUse& y) {
                  for (int k = 1; k < 4; ++k)
                    if (x.key.v[k] != y.key.v[k]) return x.key.v[k] < y.key.v[k];
                  return false;
                });
  return sorted;
}

std::vector<FacetUse> facet_uses_ref(const Elements& els) {
  std::vector<FacetUse> uses = unsorted_uses(els);
  std::sort(uses.begin(), uses.end(), [](const FacetUse& a, const FacetUse& b) {
    for (int k = 0; k < 4; ++k)
      if (a.key.v[k] != b.key.v[k]) return a.key.v[k] < b.key.v[k];
    if (a.elem.v != b.elem.v) return a.elem.v < b.elem.v;
    return a.local < b.local;
  });
  return uses;
}

namespace {

/// boundary_facets of triangles and quadrilaterals, whose facets are the edges (k, k+1): each
/// use is (larger node, element), bucketed by its smaller node, and a bucket (a node's few
/// uses) is sorted by insertion. The general path's per-use key, facet-count and std::sort
/// calls were 25% of the 2D smoothing stage (flange level 9: 201M instructions here, now 104M).
std::vector<BoundaryFacet> polygon_boundary_facets(const Elements& solid) {
  struct Use {
    std::int32_t hi;   ///< the larger node
    std::uint32_t id;  ///< element << 2 | local edge
  };
  if (solid.size() >= (std::size_t(1) << 30))
    throw LimitError("boundary_facets: " + std::to_string(solid.size()) + " elements exceed packed 32-bit facet ids");
  std::int64_t top = -1;
  for (const VertexId v : solid.node) top = std::max<std::int64_t>(top, v.v);
  auto each_edge = [&](auto&& visit) {
    for (std::size_t e = 0; e < solid.size(); ++e) {
      const std::int32_t first = solid.offset[e], n = solid.offset[e + 1] - first;
      const VertexId* v = solid.node.data() + first;
      for (std::int32_t k = 0; k < n; ++k) {
        const std::int32_t a = v[k].v, b = v[k + 1 == n ? 0 : k + 1].v;
        visit(std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(e << 2 | std::size_t(k)));
      }
    }
  };
  // Bucket = smaller id + 1 (ids are >= -1).
  std::vector<std::uint32_t> start(static_cast<std::size_t>(top + 3), 0);
  each_edge([&](std::int32_t lo, std::int32_t, std::uint32_t) { ++start[static_cast<std::size_t>(lo + 2)]; });
  for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  if (start.back() != solid.node.size())
    throw LimitError("boundary_facets: " + std::to_string(solid.node.size()) + " facet uses exceed 32-bit indices");
  std::vector<Use> uses(solid.node.size());
  each_edge([&](std::int32_t lo, std::int32_t hi, std::uint32_t id) { uses[start[static_cast<std::size_t>(lo + 1)]++] = {hi, id}; });
  // start[b] is now the end of bucket b.
  std::vector<std::uint8_t> once(solid.size() << 2, 0);
  std::size_t n_once = 0, lo = 0;
  for (std::size_t b = 0; b + 1 < start.size(); ++b) {
    const std::size_t hi = start[b];
    sort_bucket(uses.begin() + static_cast<std::ptrdiff_t>(lo), uses.begin() + static_cast<std::ptrdiff_t>(hi),
                [](const Use& x, const Use& y) { return x.hi < y.hi; });
    for (std::size_t i = lo; i < hi;) {
      std::size_t j = i + 1;
      while (j < hi && uses[j].hi == uses[i].hi) ++j;
      if (j - i == 1) once[uses[i].id] = 1, ++n_once;
      i = j;
    }
    lo = hi;
  }
  std::vector<BoundaryFacet> out;
  out.reserve(n_once);
  for (std::size_t e = 0; e < solid.size(); ++e)
    for (int f = 0; f < solid.offset[e + 1] - solid.offset[e]; ++f) {
      if (!once[(e << 2) | std::size_t(f)]) continue;
      const ElemId id{static_cast<std::int32_t>(e)};
      out.push_back({facet_of(solid, id, f), id, f});
    }
  return out;
}

}  // namespace

// The facets used once are flagged by (element, local facet) and read back in that order.
// Memory, this ran at the pipeline's peak: a use is 12 bytes, its (element, local facet) packed
// and its second and third smallest nodes, bucketed by its smallest node (counting sort); the
// full key is recomputed only when two uses agree on three nodes that are not -1 (faces of 4
// nodes). Which keys occur once does not depend on the order within a bucket.
std::vector<BoundaryFacet> boundary_facets(const Elements& solid) {
  if (std::all_of(solid.type.begin(), solid.type.end(), [](ElemType t) { return t == ElemType::Tri3 || t == ElemType::Quad4; }))
    return polygon_boundary_facets(solid);
  constexpr int facet_bits = 3;  // at most 6 facets per element
  if (solid.size() >= (std::size_t(1) << (32 - facet_bits)))
    throw LimitError("boundary_facets: " + std::to_string(solid.size()) + " elements exceed packed 32-bit facet ids");
  struct Use {
    std::uint32_t id;     ///< element << facet_bits | local facet
    std::int32_t second;  ///< key.v[1]
    std::int32_t third;   ///< key.v[2]; -1 for an edge, and then key.v[3] is -1 too
  };
  // The facets of triangles and quadrilaterals are their edges (k, k+1): the key is read off
  // the nodes (key_of(facet_of()) gives the same key, through the tables).
  auto key = [&](std::uint32_t id) {
    const auto e = static_cast<std::int32_t>(id >> facet_bits);
    const int f = static_cast<int>(id & 7u);
    const ElemType t = solid.type[static_cast<std::size_t>(e)];
    if (t != ElemType::Tri3 && t != ElemType::Quad4) return key_of(facet_of(solid, ElemId{e}, f));
    const VertexId* nodes = solid.nodes(ElemId{e});
    const int n = t == ElemType::Tri3 ? 3 : 4;
    const std::int32_t a = nodes[f].v, b = nodes[f + 1 == n ? 0 : f + 1].v;
    FacetKey k;
    k.v[0] = std::min(a, b);
    k.v[1] = std::max(a, b);
    return k;
  };
  std::int64_t top = -1;
  for (const VertexId v : solid.node) top = std::max<std::int64_t>(top, v.v);
  // Bucket = smallest id + 1 (ids are >= -1).
  std::vector<std::uint32_t> start(static_cast<std::size_t>(top + 3), 0);
  std::size_t n_uses = 0;
  for (std::size_t e = 0; e < solid.size(); ++e)
    for (int f = 0; f < n_facets(solid.type[e]); ++f, ++n_uses)
      ++start[static_cast<std::size_t>(key((std::uint32_t(e) << facet_bits) | std::uint32_t(f)).v[0] + 2)];
  if (n_uses > std::numeric_limits<std::uint32_t>::max())
    throw LimitError("boundary_facets: " + std::to_string(n_uses) + " facet uses exceed 32-bit indices");
  for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  std::vector<Use> uses(n_uses);
  for (std::size_t e = 0; e < solid.size(); ++e)
    for (int f = 0; f < n_facets(solid.type[e]); ++f) {
      const std::uint32_t id = (std::uint32_t(e) << facet_bits) | std::uint32_t(f);
      const FacetKey k = key(id);
      uses[start[static_cast<std::size_t>(k.v[0] + 1)]++] = {id, k.v[1], k.v[2]};
    }
  // start[b] is now the end of bucket b.
  std::vector<std::uint8_t> once(solid.size() << facet_bits, 0);
  std::size_t n_once = 0, lo = 0;
  for (std::size_t b = 0; b + 1 < start.size(); ++b) {
    const std::size_t hi = start[b];
    auto less = [&](const Use& x, const Use& y) {
      if (x.second != y.second) return x.second < y.second;
      if (x.third != y.third) return x.third < y.third;
      return x.third >= 0 && key(x.id).v[3] < key(y.id).v[3];
    };
    auto same = [&](const Use& x, const Use& y) {
      return x.second == y.second && x.third == y.third && (x.third < 0 || key(x.id).v[3] == key(y.id).v[3]);
    };
    std::sort(uses.begin() + static_cast<std::ptrdiff_t>(lo), uses.begin() + static_cast<std::ptrdiff_t>(hi), less);
    for (std::size_t i = lo; i < hi;) {
      std::size_t j = i + 1;
      while (j < hi && same(uses[j], uses[i])) ++j;
      if (j - i == 1) {
        once[uses[i].id] = 1;
        ++n_once;
      }
      i = j;
    }
    lo = hi;
  }
  std::vector<BoundaryFacet> out;
  out.reserve(n_once);
  for (std::size_t e = 0; e < solid.size(); ++e)
    for (int f = 0; f < n_facets(solid.type[e]); ++f) {
      if (!once[(e << facet_bits) | std::size_t(f)]) continue;
      const ElemId id{static_cast<std::int32_t>(e)};
      out.push_back({facet_of(solid, id, f), id, f});
    }
  return out;
}

namespace {

std::vector<std::array<VertexId, 2>> edge_list(const Elements& els) {
  std::vector<std::array<VertexId, 2>> edges;
  std::size_t total = 0;
  for (std::size_t e = 0; e < els.size(); ++e) total += static_cast<std::size_t>(n_edges(els.type[e]));
  edges.reserve(total);
  for (std::size_t e = 0; e < els.size(); ++e) {
    const VertexId* nodes = els.nodes(ElemId{static_cast<std::int32_t>(e)});
    if (const ElemType t = els.type[e]; t == ElemType::Tri3 || t == ElemType::Quad4) {  // edges (k, k+1)
      const int n = t == ElemType::Tri3 ? 3 : 4;
      for (int k = 0; k < n; ++k) {
        VertexId u = nodes[k], w = nodes[k + 1 == n ? 0 : k + 1];
        if (w < u) std::swap(u, w);
        edges.push_back({u, w});
      }
      continue;
    }
    for (int k = 0; k < n_edges(els.type[e]); ++k) {
      const auto [a, b] = edge_local_nodes(els.type[e], k);
      VertexId u = nodes[a], w = nodes[b];
      if (w < u) std::swap(u, w);
      edges.push_back({u, w});
    }
  }
  return edges;
}

}  // namespace

// Cost: linear, a counting sort by the smaller node then each node's few edges sorted. Memory:
// the larger node of each use (4 B), taken in runs of nodes of at most a quarter of the uses
// (one pass over the elements a run), each run's distinct larger nodes kept (4 B an edge), then
// the result at its exact size. (The larger node of every use at once was the validator's peak
// at sphere966 level 6 in session 35: 36 MB for 9 M uses beside the 15 MB result; before that,
// the list of pairs and its sorted copy, 8 B each, 48 B a tetrahedron.) On n_threads threads
// each thread passes over its own range of elements (its uses counted per node, 8 B a node a
// thread, and written after the earlier ranges' uses of the node), and the buckets are sorted
// in chunks: the same buckets, so the same edges. (All serial, it was 85 ms of the 3D
// validation's 490 on two threads, sphere966 at 995,232 tetrahedra; validate alone then took
// 426-440 ms against 434-465, and bench_mesh3d's validation showed no change beyond its noise.)
std::vector<std::array<VertexId, 2>> unique_edges(const Elements& els, std::size_t run_uses, int n_threads) {
  // Calls visit(smaller, larger) for every edge use of elements [e0, e1) (tetrahedra: every
  // pair, in any order; the result is sorted).
  const auto each_edge = [&](std::size_t e0, std::size_t e1, auto&& visit) {
    for (std::size_t e = e0; e < e1; ++e) {
      const VertexId* nodes = els.nodes(ElemId{static_cast<std::int32_t>(e)});
      const ElemType t = els.type[e];
      const auto edge = [&](std::int32_t u, std::int32_t w) { u < w ? visit(u, w) : visit(w, u); };
      if (t == ElemType::Tri3 || t == ElemType::Quad4) {  // edges (k, k+1)
        const int n = t == ElemType::Tri3 ? 3 : 4;
        for (int k = 0; k < n; ++k) edge(nodes[k].v, nodes[k + 1 == n ? 0 : k + 1].v);
      } else if (t == ElemType::Tet4) {
        for (int a = 0; a < 3; ++a)
          for (int b = a + 1; b < 4; ++b) edge(nodes[a].v, nodes[b].v);
      } else {
        for (int k = 0; k < n_edges(t); ++k) {
          const auto [a, b] = edge_local_nodes(t, k);
          edge(nodes[a].v, nodes[b].v);
        }
      }
    }
  };
  std::int64_t top = -1;
  for (const VertexId v : els.node) top = std::max<std::int64_t>(top, v.v);
  // Ids are >= -1: bucket = smaller id + 1.
  const std::size_t n_buckets = static_cast<std::size_t>(top + 2);
  // The element ranges: one a thread, none empty.
  const std::size_t n_ranges = std::max<std::size_t>(1, std::min<std::size_t>(std::size_t(std::clamp(n_threads, 1, 256)), els.size()));
  const std::size_t range = (els.size() + n_ranges - 1) / std::max<std::size_t>(n_ranges, 1);
  const auto on_ranges = [&](auto&& f) {
    for_each_chunk(els.size(), std::max<std::size_t>(range, 1), static_cast<int>(n_ranges),
                   [&](std::size_t c, std::size_t e0, std::size_t e1) { f(c, e0, e1); });
  };
  // count[c][b]: the uses of bucket b in range c.
  std::vector<std::vector<std::size_t>> count(n_ranges);
  on_ranges([&](std::size_t c, std::size_t e0, std::size_t e1) {
    count[c].assign(n_buckets, 0);
    each_edge(e0, e1, [&](std::int32_t u, std::int32_t) { ++count[c][static_cast<std::size_t>(u + 1)]; });
  });
  std::vector<std::size_t> start(n_buckets + 1, 0);
  for (std::size_t b = 0; b < n_buckets; ++b) {
    std::size_t in_bucket = 0;
    for (const std::vector<std::size_t>& k : count)
      if (!k.empty()) in_bucket += k[b];
    start[b + 1] = start[b] + in_bucket;
  }
  // Runs of buckets [b0, b1) with at most `cap` uses (a bucket above it alone), planned first
  // so that `larger` is allocated once, at the longest run's length: resized run by run it grew
  // by doubling (sphere966 at 995,232 tetrahedra, 5 runs: 11.9 MB for the longest run's 6.0 MB,
  // at mesh3d's heap peak, in the validation; massif).
  const std::size_t cap = run_uses != 0 ? run_uses : std::max<std::size_t>(start[n_buckets] / 4, std::size_t(1) << 20);
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t longest = 0;
  for (std::size_t b0 = 0; b0 < n_buckets;) {
    std::size_t b1 = b0 + 1;
    while (b1 < n_buckets && start[b1 + 1] - start[b0] <= cap) ++b1;
    runs.push_back({b0, b1});
    longest = std::max(longest, start[b1] - start[b0]);
    b0 = b1;
  }
  std::vector<std::int32_t> larger;
  larger.reserve(longest);
  // Each run's distinct larger nodes in an array of its own, of its exact size: appended to one
  // array, they grew it by doubling (11.4 MB for 4.7 MB of edges at that peak).
  std::vector<std::vector<std::int32_t>> distinct(runs.size());
  std::vector<std::size_t> n_distinct(n_buckets, 0);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto [b0, b1] = runs[r];
    larger.resize(start[b1] - start[b0]);
    on_ranges([&](std::size_t c, std::size_t e0, std::size_t e1) {
      // Range c's uses of bucket b go after the earlier ranges' (any order would do: each
      // bucket is sorted below).
      std::vector<std::size_t> fill(start.begin() + static_cast<std::ptrdiff_t>(b0),
                                    start.begin() + static_cast<std::ptrdiff_t>(b1));
      for (std::size_t b = b0; b < b1; ++b) {
        fill[b - b0] -= start[b0];
        for (std::size_t earlier = 0; earlier < c; ++earlier) fill[b - b0] += count[earlier][b];
      }
      each_edge(e0, e1, [&](std::int32_t u, std::int32_t w) {
        const std::size_t b = static_cast<std::size_t>(u + 1);
        if (b >= b0 && b < b1) larger[fill[b - b0]++] = w;
      });
    });
    // Each bucket sorted and deduplicated in place, its count of distinct larger nodes kept;
    // then they are copied out in order.
    for_each_chunk(b1 - b0, chunk_size(b1 - b0, n_threads, 4096), n_threads,
                   [&](std::size_t, std::size_t i0, std::size_t i1) {
                     for (std::size_t b = b0 + i0; b < b0 + i1; ++b) {
                       const auto first = larger.begin() + static_cast<std::ptrdiff_t>(start[b] - start[b0]),
                                  last = larger.begin() + static_cast<std::ptrdiff_t>(start[b + 1] - start[b0]);
                       sort_bucket(first, last, std::less<>{});
                       n_distinct[b] = static_cast<std::size_t>(std::unique(first, last) - first);
                     }
                   });
    std::size_t in_run = 0;
    for (std::size_t b = b0; b < b1; ++b) in_run += n_distinct[b];
    distinct[r].reserve(in_run);
    for (std::size_t b = b0; b < b1; ++b) {
      const auto first = larger.begin() + static_cast<std::ptrdiff_t>(start[b] - start[b0]);
      distinct[r].insert(distinct[r].end(), first, first + static_cast<std::ptrdiff_t>(n_distinct[b]));
    }
  }
  std::vector<std::int32_t>().swap(larger);
  std::size_t n_edges_all = 0;
  for (const std::vector<std::int32_t>& d : distinct) n_edges_all += d.size();
  std::vector<std::array<VertexId, 2>> edges;
  edges.reserve(n_edges_all);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const std::int32_t* w = distinct[r].data();
    for (std::size_t b = runs[r].first; b < runs[r].second; ++b)
      for (std::size_t k = 0; k < n_distinct[b]; ++k) edges.push_back({VertexId{static_cast<std::int32_t>(b) - 1}, VertexId{*w++}});
    std::vector<std::int32_t>().swap(distinct[r]);  // each run's nodes go as soon as they are copied
  }
  return edges;
}

namespace {

/// append_polygon_neighbours for any polygons (v may appear more than once in one).
void append_polygon_neighbours_any(const Elements& els, std::int32_t v, std::span<const std::int32_t> elems,
                                   std::vector<std::int32_t>& out, std::vector<std::uint8_t>& listed) {
  const std::size_t begin = out.size();
  for (const std::int32_t e : elems) {
    const ElemId id{e};
    const int n = els.n_nodes_of(id);
    const VertexId* ev = els.nodes(id);
    for (int k = 0; k < n; ++k) {
      if (ev[k].v != v) continue;
      for (const std::int32_t w : {ev[(k + 1) % n].v, ev[(k + n - 1) % n].v})
        if (!listed[w]) listed[w] = 1, out.push_back(w);
    }
  }
  for (std::size_t i = begin; i < out.size(); ++i) {
    listed[out[i]] = 0;
    for (std::size_t j = i; j > begin && out[j] < out[j - 1]; --j) std::swap(out[j], out[j - 1]);
  }
}

}  // namespace

// Cost: v is once in each of its polygons in a valid mesh, so each gives two neighbours, written
// through a pointer into room made once (push_back and the modulo per corner were most of the
// 2D quality pass's neighbour gathering, ~590 instructions a node at flange level 9); the rare
// polygon that holds v twice sends the node to the general version.
void append_polygon_neighbours(const Elements& els, std::int32_t v, std::span<const std::int32_t> elems,
                               std::vector<std::int32_t>& out, std::vector<std::uint8_t>& listed) {
  // Gathered on the stack for up to 32 polygons (the vector's resize zero-filled the room, a
  // memset call per node), else in `out` itself.
  constexpr std::size_t on_stack = 32;
  std::int32_t stack[2 * on_stack];
  const std::size_t begin = out.size();
  const bool small = elems.size() <= on_stack;
  if (!small) out.resize(begin + 2 * elems.size());
  std::int32_t* const first = small ? stack : out.data() + begin;
  std::int32_t* last = first;
  for (const std::int32_t e : elems) {
    const std::int32_t o = els.offset[static_cast<std::size_t>(e)];
    const int n = els.offset[static_cast<std::size_t>(e) + 1] - o;
    const VertexId* ev = els.node.data() + o;
    std::int32_t next, prev;
    bool twice;
    if (n == 3) {  // the common case, unrolled
      const std::int32_t a = ev[0].v, b = ev[1].v, c = ev[2].v;
      if (a == v) next = b, prev = c, twice = b == v || c == v;
      else if (b == v) next = c, prev = a, twice = c == v;
      else if (c == v) next = a, prev = b, twice = false;
      else continue;
    } else {
      int at = -1, hits = 0;
      for (int k = 0; k < n; ++k)
        if (ev[k].v == v) at = k, ++hits;
      if (hits == 0) continue;
      next = ev[at + 1 == n ? 0 : at + 1].v, prev = ev[at == 0 ? n - 1 : at - 1].v, twice = hits > 1;
    }
    if (twice) [[unlikely]] {
      for (const std::int32_t* w = first; w != last; ++w) listed[*w] = 0;
      out.resize(begin);
      append_polygon_neighbours_any(els, v, elems, out, listed);
      return;
    }
    if (!listed[next]) listed[next] = 1, *last++ = next;
    if (!listed[prev]) listed[prev] = 1, *last++ = prev;
  }
  const auto count = static_cast<std::size_t>(last - first);
  for (std::size_t i = 0; i < count; ++i) {
    listed[first[i]] = 0;
    for (std::size_t j = i; j > 0 && first[j] < first[j - 1]; --j) std::swap(first[j], first[j - 1]);
  }
  if (small) out.insert(out.end(), first, last);
  else out.resize(begin + count);
}

std::vector<std::array<VertexId, 2>> unique_edges_ref(const Elements& els) {
  std::vector<std::array<VertexId, 2>> edges = edge_list(els);
  std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) {
    return x[0].v != y[0].v ? x[0].v < y[0].v : x[1].v < y[1].v;
  });
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

}  // namespace febemesh
