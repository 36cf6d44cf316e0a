#pragma once
// A cell of the tree: integer anchor on a fixed lattice plus a level (STYLE.md §4, p4est quadrants).

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/box.hpp"
#include "core/cube.hpp"
#include "core/error.hpp"

namespace febemesh {

/// Deepest level: 28 in 2D, 20 in 3D (Morton keys fit 64 bits with room for the level).
template <int Dim> inline constexpr int max_level = Dim == 2 ? 28 : 20;

/// Side of the root cell in lattice units.
template <int Dim> inline constexpr std::uint32_t root_length = std::uint32_t(1) << max_level<Dim>;

template <int Dim> struct Cell {
  std::array<std::uint32_t, Dim> anchor{};  ///< lower corner, finest-level units
  std::uint8_t level = 0;

  friend bool operator==(const Cell& a, const Cell& b) {
    return a.anchor == b.anchor && a.level == b.level;
  }
  friend bool operator!=(const Cell& a, const Cell& b) { return !(a == b); }
};

/// A lattice point (cell corner) in finest-level units. The size is written std::size_t(Dim) so
/// that Dim is deduced from the other arguments (a cell, a tree) and never from the array, whose
/// size type differs from int and would make calls like locate(tree, point) fail to deduce.
template <int Dim> using LatticePoint = std::array<std::uint32_t, std::size_t(Dim)>;
/// A direction in {-1,0,1}^Dim (same deduction note as LatticePoint).
template <int Dim> using Direction = std::array<int, std::size_t(Dim)>;

/// Side of `c` in lattice units.
template <int Dim> std::uint32_t length(const Cell<Dim>& c);

/// Morton (Z-order) key of the anchor; cells sort by (key, level) so ancestors come first.
template <int Dim> std::uint64_t morton_key(const Cell<Dim>& c);
template <int Dim> bool morton_less(const Cell<Dim>& a, const Cell<Dim>& b);

/// Is `c` a valid cell: level <= max_level, anchor aligned to its size, inside the root.
template <int Dim> bool is_valid(const Cell<Dim>& c);

/// Parent; requires c.level > 0.
template <int Dim> Cell<Dim> parent(const Cell<Dim>& c);
/// Child i (0..2^Dim-1); bit d of i set = upper half along axis d. Requires level < max_level.
template <int Dim> Cell<Dim> child(const Cell<Dim>& c, int i);
template <int Dim> std::array<Cell<Dim>, Cube<Dim>::n_children> children(const Cell<Dim>& c);
/// Index (0..2^Dim-1) of `c` among its siblings; bit d set = upper half along axis d.
/// Requires c.level > 0.
template <int Dim> int child_id(const Cell<Dim>& c);
/// Ancestor of `c` at `level` (<= c.level).
template <int Dim> Cell<Dim> ancestor(const Cell<Dim>& c, int level);

/// Is `a` a strict ancestor of `d` (bit tricks), and its slow twin via lattice boxes.
template <int Dim> bool is_ancestor(const Cell<Dim>& a, const Cell<Dim>& d);
template <int Dim> bool is_ancestor_ref(const Cell<Dim>& a, const Cell<Dim>& d);

/// Same-size neighbour across facet f (face_axis/face_side); false when it leaves the root.
template <int Dim> bool face_neighbour(const Cell<Dim>& c, int f, Cell<Dim>& out);
/// Same-size neighbour at integer offset `dir` in {-1,0,1}^Dim (not all 0); false outside the root.
template <int Dim> bool neighbour(const Cell<Dim>& c, const Direction<Dim>& dir, Cell<Dim>& out);

/// Corner k of the cell as a lattice point (bit d of k = upper along d).
template <int Dim> LatticePoint<Dim> corner(const Cell<Dim>& c, int k);

/// Lattice volume (length^Dim) as a double, exact up to 2^53.
template <int Dim> double lattice_volume(const Cell<Dim>& c);

// ---- additions: exact volumes, reference twins and lattice-point keys -------------------------

/// Lattice volume length^Dim as an exact integer (the root is 2^56 in 2D, 2^60 in 3D). In a
/// complete linear tree the next leaf's Morton key is morton_key(c) + volume_units(c).
template <int Dim> std::uint64_t volume_units(const Cell<Dim>& c);
/// Slow twin of morton_key: interleaves the anchor bit by bit (axis d -> bit Dim*k + d).
template <int Dim> std::uint64_t morton_key_ref(const Cell<Dim>& c);
/// Cell whose anchor has Morton key `key` at `level` (inverse of morton_key).
template <int Dim> Cell<Dim> cell_from_key(std::uint64_t key, int level);
/// Morton key of a lattice point; coordinates may equal root_length (upper root faces).
template <int Dim> std::uint64_t point_key(const LatticePoint<Dim>& p);
template <int Dim> LatticePoint<Dim> point_from_key(std::uint64_t key);
/// point_key(corner(c, k)) for every corner k, from the anchor's key by dilated addition: the
/// side added to the bits of axis d carries through the other axes' bits once those are set
/// (no interleaving per corner).
template <int Dim> std::array<std::uint64_t, Cube<Dim>::n_corners> corner_keys(const Cell<Dim>& c);
/// Is lattice point p a corner of c, and does it lie in the closed lattice box of c.
template <int Dim> bool is_corner(const Cell<Dim>& c, const LatticePoint<Dim>& p);
template <int Dim> bool touches(const Cell<Dim>& c, const LatticePoint<Dim>& p);

namespace detail {
// Bit dilation for Morton keys (magic-number spreads). Inline because the tree's hot loops
// (refinement, balance, location) call them millions of times.
inline std::uint64_t spread_bits2(std::uint64_t x) {
  x &= 0xffffffffULL;
  x = (x | (x << 16)) & 0x0000ffff0000ffffULL;
  x = (x | (x << 8)) & 0x00ff00ff00ff00ffULL;
  x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0fULL;
  x = (x | (x << 2)) & 0x3333333333333333ULL;
  x = (x | (x << 1)) & 0x5555555555555555ULL;
  return x;
}
inline std::uint32_t compact_bits2(std::uint64_t x) {
  x &= 0x5555555555555555ULL;
  x = (x | (x >> 1)) & 0x3333333333333333ULL;
  x = (x | (x >> 2)) & 0x0f0f0f0f0f0f0f0fULL;
  x = (x | (x >> 4)) & 0x00ff00ff00ff00ffULL;
  x = (x | (x >> 8)) & 0x0000ffff0000ffffULL;
  x = (x | (x >> 16)) & 0x00000000ffffffffULL;
  return std::uint32_t(x);
}
inline std::uint64_t spread_bits3(std::uint64_t x) {  // 21 bits
  x &= 0x1fffffULL;
  x = (x | (x << 32)) & 0x1f00000000ffffULL;
  x = (x | (x << 16)) & 0x1f0000ff0000ffULL;
  x = (x | (x << 8)) & 0x100f00f00f00f00fULL;
  x = (x | (x << 4)) & 0x10c30c30c30c30c3ULL;
  x = (x | (x << 2)) & 0x1249249249249249ULL;
  return x;
}
inline std::uint32_t compact_bits3(std::uint64_t x) {
  x &= 0x1249249249249249ULL;
  x = (x | (x >> 2)) & 0x10c30c30c30c30c3ULL;
  x = (x | (x >> 4)) & 0x100f00f00f00f00fULL;
  x = (x | (x >> 8)) & 0x1f0000ff0000ffULL;
  x = (x | (x >> 16)) & 0x1f00000000ffffULL;
  x = (x | (x >> 32)) & 0x1fffffULL;
  return std::uint32_t(x);
}
template <int Dim> inline std::uint64_t interleave(const std::array<std::uint32_t, Dim>& a) {
  if constexpr (Dim == 2) {
    return spread_bits2(a[0]) | (spread_bits2(a[1]) << 1);
  } else {
    return spread_bits3(a[0]) | (spread_bits3(a[1]) << 1) | (spread_bits3(a[2]) << 2);
  }
}
template <int Dim> inline std::array<std::uint32_t, Dim> deinterleave(std::uint64_t k) {
  if constexpr (Dim == 2) {
    return {compact_bits2(k), compact_bits2(k >> 1)};
  } else {
    return {compact_bits3(k), compact_bits3(k >> 1), compact_bits3(k >> 2)};
  }
}
}  // namespace detail


// ---- inline definitions: the tree's hot loops call these millions of times -----------------

template <int Dim> inline std::uint32_t length(const Cell<Dim>& c) {
  MESH_ASSERT(c.level <= max_level<Dim>, "level=" << int(c.level));
  return std::uint32_t(1) << (max_level<Dim> - c.level);
}

template <int Dim> inline std::uint64_t morton_key(const Cell<Dim>& c) {
  return detail::interleave<Dim>(c.anchor);
}

template <int Dim> inline Cell<Dim> child(const Cell<Dim>& c, int i) {
  MESH_ASSERT(c.level < max_level<Dim>, "level=" << int(c.level));
  MESH_ASSERT(i >= 0 && i < Cube<Dim>::n_children, "i=" << i);
  Cell<Dim> ch;
  ch.level = std::uint8_t(c.level + 1);
  const std::uint32_t half = length(ch);
  for (int d = 0; d < Dim; ++d) ch.anchor[d] = c.anchor[d] + (corner_is_upper(i, d) ? half : 0);
  return ch;
}

template <int Dim> inline bool is_ancestor(const Cell<Dim>& a, const Cell<Dim>& d) {
  if (a.level >= d.level) return false;
  const std::uint32_t mask = ~(length(a) - 1);
  for (int k = 0; k < Dim; ++k) {
    if ((d.anchor[k] & mask) != a.anchor[k]) return false;
  }
  return true;
}

template <int Dim> inline bool neighbour(const Cell<Dim>& c, const Direction<Dim>& dir, Cell<Dim>& out) {
  const std::int64_t len = length(c);
  out.level = c.level;
  for (int d = 0; d < Dim; ++d) {
    const std::int64_t x = std::int64_t(c.anchor[d]) + dir[d] * len;
    if (x < 0 || x + len > std::int64_t(root_length<Dim>)) return false;
    out.anchor[d] = std::uint32_t(x);
  }
  return true;
}

template <int Dim> inline bool face_neighbour(const Cell<Dim>& c, int f, Cell<Dim>& out) {
  Direction<Dim> dir{};
  dir[face_axis(f)] = face_side(f) ? 1 : -1;
  return neighbour<Dim>(c, dir, out);
}

template <int Dim> inline LatticePoint<Dim> corner(const Cell<Dim>& c, int k) {
  LatticePoint<Dim> p;
  const std::uint32_t len = length(c);
  for (int d = 0; d < Dim; ++d) p[d] = c.anchor[d] + (corner_is_upper(k, d) ? len : 0);
  return p;
}

template <int Dim> inline std::uint64_t point_key(const LatticePoint<Dim>& p) {
  return detail::interleave<Dim>(p);
}

namespace detail {
/// The bits of axis 0 in a Morton key (axis d: shifted by d), as spread_bits2/3 leave them.
template <int Dim> inline constexpr std::uint64_t axis0_bits = Dim == 2 ? 0x5555555555555555ULL : 0x1249249249249249ULL;
}  // namespace detail

template <int Dim> inline std::array<std::uint64_t, Cube<Dim>::n_corners> corner_keys(const Cell<Dim>& c) {
  std::array<std::uint64_t, Cube<Dim>::n_corners> out;
  out[0] = morton_key(c);
  const int side_bit = Dim * (max_level<Dim> - c.level);  // length(c) in axis 0's bits
  for (int d = 0; d < Dim; ++d) {
    const std::uint64_t lane = detail::axis0_bits<Dim> << d;
    const std::uint64_t step = std::uint64_t(1) << (side_bit + d);
    for (int k = 0; k < (1 << d); ++k)  // corner k | (1 << d) = corner k moved up along d
      out[k | (1 << d)] = (((out[k] | ~lane) + step) & lane) | (out[k] & ~lane);
  }
  return out;
}

template <int Dim> inline LatticePoint<Dim> point_from_key(std::uint64_t key) {
  return detail::deinterleave<Dim>(key);
}

template <int Dim> inline bool is_corner(const Cell<Dim>& c, const LatticePoint<Dim>& p) {
  const std::uint32_t len = length(c);
  for (int d = 0; d < Dim; ++d) {
    if (p[d] != c.anchor[d] && p[d] != c.anchor[d] + len) return false;
  }
  return true;
}

template <int Dim> inline std::uint64_t volume_units(const Cell<Dim>& c) {
  return std::uint64_t(1) << (Dim * (max_level<Dim> - c.level));
}

}  // namespace febemesh
