#pragma once
// A cell of the tree: integer anchor on a fixed lattice plus a level (STYLE.md §4, p4est quadrants).

#include <array>
#include <cstdint>
#include <vector>

#include "core/box.hpp"
#include "core/cube.hpp"

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

/// A lattice point (cell corner) in finest-level units.
template <int Dim> using LatticePoint = std::array<std::uint32_t, Dim>;

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
template <int Dim> bool neighbour(const Cell<Dim>& c, const std::array<int, Dim>& dir, Cell<Dim>& out);

/// Corner k of the cell as a lattice point (bit d of k = upper along d).
template <int Dim> LatticePoint<Dim> corner(const Cell<Dim>& c, int k);

/// Lattice volume (length^Dim) as a double, exact up to 2^53.
template <int Dim> double lattice_volume(const Cell<Dim>& c);

}  // namespace febemesh
