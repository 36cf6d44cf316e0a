// Queries on the linear tree: binary searches over Morton keys, never floating comparisons
// between cells (the real point is mapped to the lattice once).

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/error.hpp"
#include "core/orthtree.hpp"

namespace febemesh {
namespace {

/// Morton keys of the leaves as an indexable sequence: computed from the cells (Orthtree) or
/// read from a flat array (LeafKeys). The searches below are the same for both.
template <int Dim> struct CellKeys {
  const Orthtree<Dim>& t;
  std::uint64_t operator[](std::size_t i) const { return morton_key(t.leaf(i)); }
  std::size_t size() const { return t.n_leaves(); }
};
struct FlatKeys {
  const std::vector<std::uint64_t>& k;
  std::uint64_t operator[](std::size_t i) const { return k[i]; }
  std::size_t size() const { return k.size(); }
};

/// std::upper_bound / std::lower_bound over keys[lo, hi).
template <class Keys> std::size_t upper_bound_key(const Keys& keys, std::size_t lo, std::size_t hi, std::uint64_t key) {
  for (std::size_t n = hi - lo; n > 0;) {
    const std::size_t half = n / 2;
    if (!(key < keys[lo + half])) {
      lo += half + 1;
      n -= half + 1;
    } else {
      n = half;
    }
  }
  return lo;
}
template <class Keys> std::size_t lower_bound_key(const Keys& keys, std::size_t lo, std::size_t hi, std::uint64_t key) {
  for (std::size_t n = hi - lo; n > 0;) {
    const std::size_t half = n / 2;
    if (keys[lo + half] < key) {
      lo += half + 1;
      n -= half + 1;
    } else {
      n = half;
    }
  }
  return lo;
}

/// upper_bound_key over all keys, searched outward from `hint` (galloping, then binary search):
/// O(log distance), the same answer. Successive queries at nearby keys pass the previous one.
template <class Keys> std::size_t upper_bound_near(const Keys& keys, std::size_t hint, std::uint64_t key) {
  const std::size_t n = keys.size();
  if (hint > n) hint = n;
  std::size_t lo = 0, hi = n, step = 1;
  if (hint < n && !(key < keys[hint])) {  // the answer is after hint
    lo = hint + 1;
    for (;;) {
      const std::size_t probe = lo - 1 + step;
      if (probe >= n) {
        hi = n;
        break;
      }
      if (key < keys[probe]) {
        hi = probe;
        break;
      }
      lo = probe + 1;
      step *= 2;
    }
  } else {  // the answer is at or before hint
    hi = hint;
    for (;;) {
      if (hi == 0) return 0;
      const std::size_t probe = hi >= step ? hi - step : 0;
      if (key < keys[probe]) {
        hi = probe;
        step *= 2;
      } else {
        lo = probe + 1;
        break;
      }
    }
  }
  return upper_bound_key(keys, lo, hi, key);
}

/// Index of the last leaf whose Morton key is <= key, or no_leaf. In a linear tree at most one
/// leaf has a given key, so this is the only candidate to contain a cell anchored at `key`.
template <class Keys> std::size_t last_at_or_before(const Keys& keys, std::uint64_t key) {
  const std::size_t it = upper_bound_key(keys, 0, keys.size(), key);
  if (it == 0) return no_leaf;
  return it - 1;
}

/// First leaf with Morton key >= key.
template <class Keys> std::size_t first_at_or_after(const Keys& keys, std::uint64_t key) {
  return lower_bound_key(keys, 0, keys.size(), key);
}

template <int Dim> bool contains_or_equals(const Cell<Dim>& a, const Cell<Dim>& c) {
  return a == c || is_ancestor(a, c);
}

template <int Dim, class Keys> std::size_t covering_leaf(const Orthtree<Dim>& t, const Keys& keys, const Cell<Dim>& c) {
  const std::size_t j = last_at_or_before(keys, morton_key(c));
  if (j == no_leaf || !contains_or_equals(t.leaf(j), c)) return no_leaf;
  return j;
}

/// The same searched from a hint (upper_bound_near).
template <int Dim, class Keys>
std::size_t covering_leaf_near(const Orthtree<Dim>& t, const Keys& keys, const Cell<Dim>& c, std::size_t hint) {
  const std::size_t it = upper_bound_near(keys, hint, morton_key(c));
  if (it == 0 || !contains_or_equals(t.leaf(it - 1), c)) return no_leaf;
  return it - 1;
}

/// The finest-level cell anchored at p; false when p lies outside the root.
template <int Dim> bool unit_cell_at(const LatticePoint<Dim>& p, Cell<Dim>& unit) {
  for (int d = 0; d < Dim; ++d) {
    if (p[d] >= root_length<Dim>) return false;
  }
  unit.anchor = p;
  unit.level = std::uint8_t(max_level<Dim>);
  return true;
}

template <int Dim, class Keys> std::size_t leaf_at(const Orthtree<Dim>& t, const Keys& keys, const LatticePoint<Dim>& p) {
  Cell<Dim> unit;
  return unit_cell_at(p, unit) ? covering_leaf(t, keys, unit) : no_leaf;
}

/// Leaves inside cell c that touch its facet on side `side` of `axis`, depth first in Morton order.
template <int Dim, class Keys>
void facet_leaves(const Orthtree<Dim>& t, const Keys& keys, const Cell<Dim>& c, int axis, int side,
                  std::vector<std::size_t>& out, std::size_t hint) {
  const std::size_t j = hint == no_leaf ? covering_leaf(t, keys, c) : covering_leaf_near(t, keys, c, hint);
  if (j != no_leaf) {
    out.push_back(j);
    return;
  }
  // Stop where c holds no leaf at all (only in an incomplete tree).
  const std::size_t first = first_at_or_after(keys, morton_key(c));
  if (first == t.n_leaves() || keys[first] >= morton_key(c) + volume_units(c)) return;
  for (int i = 0; i < Cube<Dim>::n_children; ++i) {
    if (int((i >> axis) & 1) == side) facet_leaves(t, keys, child(c, i), axis, side, out, hint);
  }
}

template <int Dim, class Keys>
void neighbours_across(const Orthtree<Dim>& t, const Keys& keys, std::size_t i, int f, std::vector<std::size_t>& out,
                       std::size_t hint = no_leaf) {
  MESH_ASSERT(i < t.n_leaves(), "leaf " << i << " of " << t.n_leaves());
  MESH_ASSERT(f >= 0 && f < Cube<Dim>::n_faces, "facet " << f);
  out.clear();
  Cell<Dim> n;
  if (!face_neighbour(t.leaf(i), f, n)) return;
  // The neighbour's leaves that touch leaf i lie on n's facet facing back: the opposite side.
  facet_leaves(t, keys, n, face_axis(f), 1 - face_side(f), out, hint);
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
  // Children's leaves are contiguous sub-ranges of [lo, hi) split at the children's keys; the
  // split is searched for only around the children that meet the box (a small box meets one
  // or two of them: the searches, a Morton key per probe, were most of this query's cost).
  const auto& L = t.leaves();
  auto first_at_or_after = [&](std::size_t from, const Cell<Dim>& cell) {
    return std::size_t(std::lower_bound(L.begin() + std::ptrdiff_t(from), L.begin() + std::ptrdiff_t(hi), morton_key(cell),
                                        [](const Cell<Dim>& x, std::uint64_t k) { return morton_key(x) < k; }) -
                       L.begin());
  };
  std::size_t begin = lo;  // child i's first leaf when `known`, else a lower bound of it
  bool known = true;
  for (int i = 0; i < Cube<Dim>::n_children; ++i) {
    const Cell<Dim> ch = child(c, i);
    if (!geometry(t, ch).overlaps(b)) {
      known = false;
      continue;
    }
    if (!known) begin = first_at_or_after(begin, ch);
    const std::size_t end = i + 1 < Cube<Dim>::n_children ? first_at_or_after(begin, child(c, i + 1)) : hi;
    box_leaves(t, ch, begin, end, b, out);
    begin = end;
    known = true;
  }
}

}  // namespace

template <int Dim> std::size_t locate(const Orthtree<Dim>& t, const LatticePoint<Dim>& p) {
  return leaf_at(t, CellKeys<Dim>{t}, p);
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
  return covering_leaf(t, CellKeys<Dim>{t}, c);
}

template <int Dim> std::vector<std::size_t> face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f) {
  std::vector<std::size_t> out;
  neighbours_across(t, CellKeys<Dim>{t}, i, f, out);
  return out;
}

template <int Dim> void face_neighbours(const Orthtree<Dim>& t, std::size_t i, int f, std::vector<std::size_t>& out) {
  neighbours_across(t, CellKeys<Dim>{t}, i, f, out);
}

template <int Dim> LeafKeys<Dim>::LeafKeys(const Orthtree<Dim>& t) : tree_(&t), keys_(t.n_leaves()) {
  for (std::size_t i = 0; i < t.n_leaves(); ++i) keys_[i] = morton_key(t.leaf(i));
}

template <int Dim> std::size_t LeafKeys<Dim>::find_covering_leaf(const Cell<Dim>& c) const {
  return covering_leaf(*tree_, FlatKeys{keys_}, c);
}

template <int Dim> std::size_t LeafKeys<Dim>::locate(const LatticePoint<Dim>& p) const {
  return leaf_at(*tree_, FlatKeys{keys_}, p);
}

template <int Dim> std::size_t LeafKeys<Dim>::locate_near(const LatticePoint<Dim>& p, std::size_t hint) const {
  Cell<Dim> unit;
  return unit_cell_at(p, unit) ? covering_leaf_near(*tree_, FlatKeys{keys_}, unit, hint) : no_leaf;
}

template <int Dim> void LeafKeys<Dim>::face_neighbours(std::size_t i, int f, std::vector<std::size_t>& out) const {
  // Most neighbours are near leaf i in Morton order: the searches start there.
  neighbours_across(*tree_, FlatKeys{keys_}, i, f, out, i);
}

template <int Dim> std::vector<std::size_t> leaves_in_box(const Orthtree<Dim>& t, const Box<Dim>& b) {
  std::vector<std::size_t> out;
  // The search starts at the smallest cell holding the lattice units from one unit below b to
  // one above (the margin dwarfs the rounding of the map to the lattice): every leaf that meets
  // b is in it or holds it. From the root, a small box cost a binary search per level
  // (segment_enters_kept, flange level 9: 15,000 instructions a query).
  LatticePoint<Dim> x0, x1;
  bool finite = true;
  for (int d = 0; d < Dim; ++d) {
    const double u0 = std::floor((b.lo[d] - t.root_box().lo[d]) / t.unit()) - 1.0;
    const double u1 = std::floor((b.hi[d] - t.root_box().lo[d]) / t.unit()) + 1.0;
    if (!(u0 <= u1)) {  // NaN or an empty box: the plain search decides
      finite = false;
      break;
    }
    const double top = double(root_length<Dim> - 1);
    x0[d] = std::uint32_t(std::clamp(u0, 0.0, top));
    x1[d] = std::uint32_t(std::clamp(u1, 0.0, top));
  }
  if (!finite) {
    box_leaves(t, Cell<Dim>{}, 0, t.n_leaves(), b, out);
    return out;
  }
  std::uint32_t differ = 0;
  for (int d = 0; d < Dim; ++d) differ |= x0[d] ^ x1[d];
  Cell<Dim> a;
  a.level = std::uint8_t(max_level<Dim> - std::bit_width(differ));
  for (int d = 0; d < Dim; ++d) a.anchor[d] = x0[d] & ~(length(a) - 1);
  const CellKeys<Dim> keys{t};
  const std::size_t j = covering_leaf(t, keys, a);
  if (j != no_leaf) {
    if (geometry(t, t.leaf(j)).overlaps(b)) out.push_back(j);
    return out;
  }
  const std::size_t lo = first_at_or_after(keys, morton_key(a));
  const std::size_t hi = lower_bound_key(keys, lo, keys.size(), morton_key(a) + volume_units(a));
  box_leaves(t, a, lo, hi, b, out);
  return out;
}

#define FEBEMESH_INSTANTIATE_QUERIES(D)                                                       \
  template std::size_t locate<D>(const Orthtree<D>&, const Point<D>&);                        \
  template std::size_t locate<D>(const Orthtree<D>&, const LatticePoint<D>&);                 \
  template std::size_t find_covering_leaf<D>(const Orthtree<D>&, const Cell<D>&);             \
  template std::vector<std::size_t> face_neighbours<D>(const Orthtree<D>&, std::size_t, int); \
  template void face_neighbours<D>(const Orthtree<D>&, std::size_t, int, std::vector<std::size_t>&); \
  template std::vector<std::size_t> leaves_in_box<D>(const Orthtree<D>&, const Box<D>&);     \
  template class LeafKeys<D>;

FEBEMESH_INSTANTIATE_QUERIES(2)
FEBEMESH_INSTANTIATE_QUERIES(3)

}  // namespace febemesh
