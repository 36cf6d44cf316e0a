// Queries on the linear tree: binary searches over Morton keys, never floating comparisons
// between cells (the real point is mapped to the lattice once).

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/orthtree.hpp"

namespace febemesh {
namespace {

/// Index of the last leaf whose Morton key is <= key, or no_leaf. In a linear tree at most one
/// leaf has a given key, so this is the only candidate to contain a cell anchored at `key`.
template <int Dim> std::size_t last_at_or_before(const Orthtree<Dim>& t, std::uint64_t key) {
  const auto& L = t.leaves();
  const auto it = std::upper_bound(L.begin(), L.end(), key, [](std::uint64_t k, const Cell<Dim>& c) {
    return k < morton_key(c);
  });
  if (it == L.begin()) return no_leaf;
  return std::size_t(it - L.begin()) - 1;
}

/// First leaf with Morton key >= key.
template <int Dim> std::size_t first_at_or_after(const Orthtree<Dim>& t, std::uint64_t key) {
  const auto& L = t.leaves();
  return std::size_t(std::lower_bound(L.begin(), L.end(), key, [](const Cell<Dim>& c, std::uint64_t k) {
                       return morton_key(c) < k;
                     }) - L.begin());
}

template <int Dim> bool contains_or_equals(const Cell<Dim>& a, const Cell<Dim>& c) {
  return a == c || is_ancestor(a, c);
}

/// Leaves inside cell c that touch its facet on side `side` of `axis`, depth first in Morton order.
template <int Dim>
void facet_leaves(const Orthtree<Dim>& t, const Cell<Dim>& c, int axis, int side, std::vector<std::size_t>& out) {
  const std::size_t j = find_covering_leaf(t, c);
  if (j != no_leaf) {
    out.push_back(j);
    return;
  }
  // Stop where c holds no leaf at all (only in an incomplete tree).
  const std::size_t first = first_at_or_after(t, morton_key(c));
  if (first == t.n_leaves() || morton_key(t.leaf(first)) >= morton_key(c) + volume_units(c)) return;
  for (int i = 0; i < Cube<Dim>::n_children; ++i) {
    if (int((i >> axis) & 1) == side) facet_leaves(t, child(c, i), axis, side, out);
  }
}

template <int Dim>
void box_leaves(const Orthtree<Dim>& t, const Cell<Dim>& c, std::size_t lo, std::size_t hi,
                const Box<Dim>& b, std::vector<std::size_t>& out) {
  if (lo >= hi || !geometry(t, c).overlaps(b)) return;
  if (hi - lo == 1 && t.leaf(lo) == c) {
    out.push_back(lo);
    return;
  }
  if (c.level >= max_level<Dim>) return;
  // Children's leaves are contiguous sub-ranges of [lo, hi) split at the children's keys.
  std::size_t begin = lo;
  for (int i = 0; i < Cube<Dim>::n_children; ++i) {
    const Cell<Dim> ch = child(c, i);
    std::size_t end = hi;
    if (i + 1 < Cube<Dim>::n_children) {
      const std::uint64_t next = morton_key(child(c, i + 1));
      const auto& L = t.leaves();
      end = std::size_t(std::lower_bound(L.begin() + std::ptrdiff_t(begin), L.begin() + std::ptrdiff_t(hi), next,
                                         [](const Cell<Dim>& x, std::uint64_t k) { return morton_key(x) < k; }) -
                        L.begin());
    }
    box_leaves(t, ch, begin, end, b, out);
    begin = end;
  }
}

}  // namespace

template <int Dim> std::size_t locate(const Orthtree<Dim>& t, const LatticePoint<Dim>& p) {
  for (int d = 0; d < Dim; ++d) {
    if (p[d] >= root_length<Dim>) return no_leaf;
  }
  Cell<Dim> unit;
  unit.anchor = p;
  unit.level = std::uint8_t(max_level<Dim>);
  return find_covering_leaf(t, unit);
}

template <int Dim> std::size_t locate(const Orthtree<Dim>& t, const Point<Dim>& x) {
  LatticePoint<Dim> p;
  for (int d = 0; d < Dim; ++d) {
    const double lo = t.root_box().lo[d], hi = t.root_box().hi[d];
    if (!(x[d] >= lo && x[d] <= hi)) return no_leaf;  // also rejects NaN
    const double u = std::floor((x[d] - lo) / t.unit());
    // Points on the upper root face belong to the last cell along that axis.
    p[d] = u >= double(root_length<Dim>) ? root_length<Dim> - 1 : std::uint32_t(std::max(u, 0.0));
  }
  return locate(t, p);
}

template <int Dim> std::size_t find_covering_leaf(const Orthtree<Dim>& t, const Cell<Dim>& c) {
  const std::size_t j = last_at_or_before(t, morton_key(c));
  if (j == no_leaf || !contains_or_equals(t.leaf(j), c)) return no_leaf;
  return j;
}

template <int Dim> std::vector<std::size_t> face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f) {
  std::vector<std::size_t> out;
  face_neighbours(t, i, f, out);
  return out;
}

template <int Dim> void face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f, std::vector<std::size_t>& out) {
  MESH_ASSERT(i < t.n_leaves(), "leaf " << i << " of " << t.n_leaves());
  MESH_ASSERT(f >= 0 && f < Cube<Dim>::n_faces, "facet " << f);
  out.clear();
  Cell<Dim> n;
  if (!face_neighbour(t.leaf(i), f, n)) return;
  // The neighbour's leaves that touch leaf i lie on n's facet facing back: the opposite side.
  facet_leaves(t, n, face_axis(f), 1 - face_side(f), out);
}

template <int Dim> std::vector<std::size_t> leaves_in_box(const Orthtree<Dim>& t, const Box<Dim>& b) {
  std::vector<std::size_t> out;
  box_leaves(t, Cell<Dim>{}, 0, t.n_leaves(), b, out);
  return out;
}

#define FEBEMESH_INSTANTIATE_QUERIES(D)                                                       \
  template std::size_t locate<D>(const Orthtree<D>&, const Point<D>&);                        \
  template std::size_t locate<D>(const Orthtree<D>&, const LatticePoint<D>&);                 \
  template std::size_t find_covering_leaf<D>(const Orthtree<D>&, const Cell<D>&);             \
  template std::vector<std::size_t> face_neighbours<D>(const Orthtree<D>&, std::size_t, int); \
  template void face_neighbours<D>(const Orthtree<D>&, std::size_t, int, std::vector<std::size_t>&); \
  template std::vector<std::size_t> leaves_in_box<D>(const Orthtree<D>&, const Box<D>&);

FEBEMESH_INSTANTIATE_QUERIES(2)
FEBEMESH_INSTANTIATE_QUERIES(3)

}  // namespace febemesh
