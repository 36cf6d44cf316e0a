// Cells on the fixed lattice: Morton keys, family relations and neighbours by integer
// arithmetic only (p4est quadrant bit tricks), with slow twins for the tests.

#include "core/cell.hpp"

#include "core/error.hpp"

namespace febemesh {

template <int Dim> bool morton_less(const Cell<Dim>& a, const Cell<Dim>& b) {
  const std::uint64_t ka = morton_key(a), kb = morton_key(b);
  return ka < kb || (ka == kb && a.level < b.level);
}

template <int Dim> bool is_valid(const Cell<Dim>& c) {
  if (c.level > max_level<Dim>) return false;
  const std::uint32_t len = length(c);
  for (int d = 0; d < Dim; ++d) {
    if (c.anchor[d] % len != 0 || c.anchor[d] >= root_length<Dim>) return false;
  }
  return true;
}

template <int Dim> Cell<Dim> parent(const Cell<Dim>& c) {
  MESH_ASSERT(c.level > 0, "the root has no parent");
  Cell<Dim> p;
  p.level = std::uint8_t(c.level - 1);
  const std::uint32_t mask = ~(length(p) - 1);
  for (int d = 0; d < Dim; ++d) p.anchor[d] = c.anchor[d] & mask;
  return p;
}

template <int Dim> std::array<Cell<Dim>, Cube<Dim>::n_children> children(const Cell<Dim>& c) {
  std::array<Cell<Dim>, Cube<Dim>::n_children> out;
  for (int i = 0; i < Cube<Dim>::n_children; ++i) out[i] = child(c, i);
  return out;
}

template <int Dim> int child_id(const Cell<Dim>& c) {
  MESH_ASSERT(c.level > 0, "the root has no siblings");
  const std::uint32_t len = length(c);
  int id = 0;
  for (int d = 0; d < Dim; ++d) id |= ((c.anchor[d] & len) ? 1 : 0) << d;
  return id;
}

template <int Dim> Cell<Dim> ancestor(const Cell<Dim>& c, int level) {
  MESH_ASSERT(level >= 0 && level <= c.level, "level=" << level << " c.level=" << int(c.level));
  Cell<Dim> a;
  a.level = std::uint8_t(level);
  const std::uint32_t mask = ~(length(a) - 1);
  for (int d = 0; d < Dim; ++d) a.anchor[d] = c.anchor[d] & mask;
  return a;
}

template <int Dim> bool is_ancestor_ref(const Cell<Dim>& a, const Cell<Dim>& d) {
  // Box containment in 64-bit lattice coordinates: no bit tricks.
  if (a.level >= d.level) return false;
  for (int k = 0; k < Dim; ++k) {
    const std::uint64_t alo = a.anchor[k], ahi = alo + length(a);
    const std::uint64_t dlo = d.anchor[k], dhi = dlo + length(d);
    if (dlo < alo || dhi > ahi) return false;
  }
  return true;
}

template <int Dim> double lattice_volume(const Cell<Dim>& c) { return double(volume_units(c)); }

template <int Dim> std::uint64_t morton_key_ref(const Cell<Dim>& c) {
  std::uint64_t key = 0;
  for (int bit = 0; bit < max_level<Dim>; ++bit) {
    for (int d = 0; d < Dim; ++d) {
      key |= std::uint64_t((c.anchor[d] >> bit) & 1u) << (Dim * bit + d);
    }
  }
  return key;
}

template <int Dim> Cell<Dim> cell_from_key(std::uint64_t key, int level) {
  Cell<Dim> c;
  c.anchor = detail::deinterleave<Dim>(key);
  c.level = std::uint8_t(level);
  return c;
}

template <int Dim> bool touches(const Cell<Dim>& c, const LatticePoint<Dim>& p) {
  const std::uint32_t len = length(c);
  for (int d = 0; d < Dim; ++d) {
    if (p[d] < c.anchor[d] || p[d] > c.anchor[d] + len) return false;
  }
  return true;
}

#define FEBEMESH_INSTANTIATE_CELL(D)                                                        \
  template bool morton_less<D>(const Cell<D>&, const Cell<D>&);                             \
  template bool is_valid<D>(const Cell<D>&);                                                \
  template Cell<D> parent<D>(const Cell<D>&);                                               \
  template std::array<Cell<D>, Cube<D>::n_children> children<D>(const Cell<D>&);            \
  template int child_id<D>(const Cell<D>&);                                                 \
  template Cell<D> ancestor<D>(const Cell<D>&, int);                                        \
  template bool is_ancestor_ref<D>(const Cell<D>&, const Cell<D>&);                         \
  template double lattice_volume<D>(const Cell<D>&);                                        \
  template std::uint64_t morton_key_ref<D>(const Cell<D>&);                                 \
  template Cell<D> cell_from_key<D>(std::uint64_t, int);                                    \
  template bool touches<D>(const Cell<D>&, const LatticePoint<D>&);

FEBEMESH_INSTANTIATE_CELL(2)
FEBEMESH_INSTANTIATE_CELL(3)

static_assert(sizeof(Cell<2>) == 12, "a 2D leaf must stay 12 bytes");
static_assert(sizeof(Cell<3>) == 16, "a 3D leaf must stay 16 bytes");

}  // namespace febemesh
