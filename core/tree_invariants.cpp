// Tree invariants (STYLE.md §7): fast checks by Morton-key arithmetic, and slow reference twins
// that compare every pair of leaves through their lattice boxes.

#include <algorithm>

#include "core/orthtree.hpp"

namespace febemesh {
namespace {

/// Lattice box of a cell as 64-bit half-open intervals per axis.
template <int Dim> struct LatticeBox {
  std::array<std::uint64_t, Dim> lo{}, hi{};
  explicit LatticeBox(const Cell<Dim>& c) {
    for (int d = 0; d < Dim; ++d) {
      lo[d] = c.anchor[d];
      hi[d] = lo[d] + (std::uint64_t(1) << (max_level<Dim> - c.level));
    }
  }
};

/// How the closed boxes of a and b meet: -1 apart, otherwise the dimension of their intersection
/// (Dim = overlapping interiors, Dim-1 = shared facet part, ..., 0 = a corner).
template <int Dim> int contact_dimension(const Cell<Dim>& a, const Cell<Dim>& b) {
  const LatticeBox<Dim> A(a), B(b);
  int dim = 0;
  for (int d = 0; d < Dim; ++d) {
    const std::uint64_t lo = std::max(A.lo[d], B.lo[d]), hi = std::min(A.hi[d], B.hi[d]);
    if (lo > hi) return -1;
    if (lo < hi) ++dim;
  }
  return dim;
}

template <int Dim> void all_directions(BalanceKind kind, std::vector<std::array<int, Dim>>& dirs) {
  dirs.clear();
  if (kind == BalanceKind::Face) {
    for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
      std::array<int, Dim> d{};
      d[face_axis(f)] = face_side(f) ? 1 : -1;
      dirs.push_back(d);
    }
    return;
  }
  int n = 1;
  for (int d = 0; d < Dim; ++d) n *= 3;
  for (int code = 0; code < n; ++code) {
    std::array<int, Dim> d{};
    int c = code;
    bool zero = true;
    for (int k = 0; k < Dim; ++k) {
      d[k] = c % 3 - 1;
      c /= 3;
      zero = zero && d[k] == 0;
    }
    if (!zero) dirs.push_back(d);
  }
}

}  // namespace

template <int Dim> bool is_sorted_and_linear(const Orthtree<Dim>& t) {
  const auto& L = t.leaves();
  for (std::size_t i = 0; i < L.size(); ++i) {
    if (!is_valid(L[i])) return false;
    // Descendants follow their ancestor immediately in Morton order, so checking neighbours in
    // the array finds any overlap.
    if (i > 0 && (!morton_less(L[i - 1], L[i]) || is_ancestor(L[i - 1], L[i]))) return false;
  }
  return true;
}

template <int Dim> bool is_sorted_and_linear_ref(const Orthtree<Dim>& t) {
  const auto& L = t.leaves();
  for (std::size_t i = 0; i < L.size(); ++i) {
    if (!is_valid(L[i])) return false;
    if (i > 0) {
      const std::uint64_t a = morton_key_ref(L[i - 1]), b = morton_key_ref(L[i]);
      if (a > b || (a == b && L[i - 1].level >= L[i].level)) return false;
    }
    for (std::size_t j = i + 1; j < L.size(); ++j) {
      if (contact_dimension(L[i], L[j]) == Dim) return false;
    }
  }
  return true;
}

template <int Dim> bool is_complete(const Orthtree<Dim>& t) {
  // In a complete linear tree each leaf starts where the previous one's key range ends.
  std::uint64_t expected = 0;
  for (const auto& c : t.leaves()) {
    if (!is_valid(c) || morton_key(c) != expected) return false;
    expected += volume_units(c);
  }
  return !t.leaves().empty() && expected == volume_units(Cell<Dim>{});
}

template <int Dim> bool is_complete_ref(const Orthtree<Dim>& t) {
  if (!is_sorted_and_linear_ref(t)) return false;  // includes: no two interiors overlap
  long double volume = 0;
  for (const auto& c : t.leaves()) volume += (long double)lattice_volume(c);
  return volume == (long double)lattice_volume(Cell<Dim>{});
}

template <int Dim> bool is_balanced(const Orthtree<Dim>& t, BalanceKind kind) {
  // Enough to check that no neighbour is two or more levels coarser: a neighbour two levels
  // finer sees this leaf as two levels coarser from its side.
  std::vector<std::array<int, Dim>> dirs;
  all_directions<Dim>(kind, dirs);
  for (const auto& c : t.leaves()) {
    if (c.level < 2) continue;
    for (const auto& dir : dirs) {
      Cell<Dim> n;
      if (!neighbour<Dim>(c, dir, n)) continue;
      const std::size_t j = locate(t, n.anchor);
      if (j != no_leaf && t.leaf(j).level + 1 < c.level) return false;
    }
  }
  return true;
}

template <int Dim> bool is_balanced_ref(const Orthtree<Dim>& t, BalanceKind kind) {
  const auto& L = t.leaves();
  const int needed = kind == BalanceKind::Face ? Dim - 1 : 0;
  for (std::size_t i = 0; i < L.size(); ++i) {
    for (std::size_t j = i + 1; j < L.size(); ++j) {
      const int contact = contact_dimension(L[i], L[j]);
      if (contact >= needed && contact < Dim && std::abs(int(L[i].level) - int(L[j].level)) > 1) {
        return false;
      }
    }
  }
  return true;
}

#define FEBEMESH_INSTANTIATE_INVARIANTS(D)                                      \
  template bool is_sorted_and_linear<D>(const Orthtree<D>&);                    \
  template bool is_sorted_and_linear_ref<D>(const Orthtree<D>&);                \
  template bool is_complete<D>(const Orthtree<D>&);                             \
  template bool is_complete_ref<D>(const Orthtree<D>&);                         \
  template bool is_balanced<D>(const Orthtree<D>&, BalanceKind);                \
  template bool is_balanced_ref<D>(const Orthtree<D>&, BalanceKind);

FEBEMESH_INSTANTIATE_INVARIANTS(2)
FEBEMESH_INSTANTIATE_INVARIANTS(3)

}  // namespace febemesh
