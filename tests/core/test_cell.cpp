// Tests for core/cell.hpp: bit tricks against their slow twins, in both dimensions.

#include <catch2/catch.hpp>

#include "core/cell.hpp"
#include "core/cell_arbitrary.hpp"
#include "property.hpp"

using namespace febemesh;

TEST_CASE("cells stay small", "[cell]") {
  STATIC_REQUIRE(sizeof(Cell<2>) == 12);
  STATIC_REQUIRE(sizeof(Cell<3>) == 16);
  STATIC_REQUIRE(max_level<2> == 28);
  STATIC_REQUIRE(max_level<3> == 20);
}

TEMPLATE_TEST_CASE_SIG("cell family by hand", "[cell]", ((int Dim), Dim), 2, 3) {
  const Cell<Dim> root{};
  REQUIRE(length(root) == root_length<Dim>);
  REQUIRE(is_valid(root));
  const auto kids = children(root);
  for (int i = 0; i < Cube<Dim>::n_children; ++i) {
    REQUIRE(parent(kids[i]) == root);
    REQUIRE(child_id(kids[i]) == i);
    REQUIRE(is_ancestor(root, kids[i]));
    REQUIRE_FALSE(is_ancestor(kids[i], root));
    if (i > 0) REQUIRE(morton_less(kids[i - 1], kids[i]));
  }
  REQUIRE(morton_less(root, kids[0]));  // ancestor first at equal keys
  REQUIRE_FALSE(is_ancestor(root, root));
  // Child n_children-1 is the upper corner: anchor = half along every axis.
  for (int d = 0; d < Dim; ++d) REQUIRE(kids.back().anchor[d] == root_length<Dim> / 2);
  Cell<Dim> n;
  REQUIRE_FALSE(face_neighbour(root, 0, n));
  REQUIRE(face_neighbour(kids[0], 1, n));
  REQUIRE(n == kids[1]);
  REQUIRE_FALSE(face_neighbour(kids[0], 0, n));
  // Misaligned anchors and too deep levels are not cells.
  Cell<Dim> bad = kids[1];
  bad.anchor[0] += 1;
  REQUIRE_FALSE(is_valid(bad));
  bad = root;
  bad.level = max_level<Dim> + 1;
  REQUIRE_FALSE(is_valid(bad));
  // Lattice points on the upper root faces have keys too.
  LatticePoint<Dim> top;
  top.fill(root_length<Dim>);
  REQUIRE(point_from_key<Dim>(point_key<Dim>(top)) == top);
  REQUIRE(corner(root, Cube<Dim>::n_corners - 1) == top);
  REQUIRE(is_corner(root, top));
  REQUIRE(corner_keys(root)[Cube<Dim>::n_corners - 1] == point_key<Dim>(top));
}

TEMPLATE_TEST_CASE_SIG("cell bit tricks agree with their slow twins", "[cell][property]", ((int Dim), Dim), 2, 3) {
  test::prop("morton_key == morton_key_ref and keys round-trip", 200, [](const Cell<Dim>& c) {
    RC_ASSERT(is_valid(c));
    RC_ASSERT(morton_key(c) == morton_key_ref(c));
    RC_ASSERT(cell_from_key<Dim>(morton_key(c), c.level) == c);
  });
  test::prop("corner_keys are the corners' point keys", 200, [](const Cell<Dim>& c) {
    const auto keys = corner_keys(c);
    for (int k = 0; k < Cube<Dim>::n_corners; ++k) RC_ASSERT(keys[k] == point_key<Dim>(corner(c, k)));
  });
  test::prop("point keys round-trip up to root_length inclusive", 200, [](std::array<std::uint32_t, Dim> raw) {
    LatticePoint<Dim> p;
    for (int d = 0; d < Dim; ++d) p[d] = raw[d] % (root_length<Dim> + 1);
    RC_ASSERT(point_from_key<Dim>(point_key<Dim>(p)) == p);
  });
  test::prop("parent, child, child_id and ancestor agree", 200, [](const Cell<Dim>& c) {
    if (c.level < max_level<Dim>) {
      const auto kids = children(c);
      std::uint64_t volume = 0;
      for (int i = 0; i < Cube<Dim>::n_children; ++i) {
        RC_ASSERT(is_valid(kids[i]));
        RC_ASSERT(parent(kids[i]) == c);
        RC_ASSERT(child_id(kids[i]) == i);
        RC_ASSERT(is_ancestor(c, kids[i]));
        RC_ASSERT(is_ancestor_ref(c, kids[i]));
        volume += volume_units(kids[i]);
        // Children are contiguous in key space, in child order.
        RC_ASSERT(morton_key(kids[i]) == morton_key(c) + std::uint64_t(i) * volume_units(kids[i]));
      }
      RC_ASSERT(volume == volume_units(c));
      RC_ASSERT(double(volume) == lattice_volume(c));
    }
    for (int l = 0; l <= c.level; ++l) {
      const Cell<Dim> a = ancestor(c, l);
      RC_ASSERT(is_valid(a));
      RC_ASSERT(is_ancestor(a, c) == (l < c.level));
      RC_ASSERT(is_ancestor_ref(a, c) == (l < c.level));
    }
  });
  test::prop("is_ancestor == is_ancestor_ref on arbitrary pairs", 300, [] {
    // Shallow cells make ancestry likely enough to exercise both answers.
    const auto a = *test::gen_cell<Dim>(4);
    const auto b = *rc::gen::oneOf(test::gen_cell<Dim>(6), rc::gen::just(a));
    RC_ASSERT(is_ancestor(a, b) == is_ancestor_ref(a, b));
    RC_ASSERT(is_ancestor(b, a) == is_ancestor_ref(b, a));
    // Morton order puts an ancestor before its descendants.
    if (is_ancestor(a, b)) RC_ASSERT(morton_less(a, b));
  });
  test::prop("neighbours go and come back", 200, [](const Cell<Dim>& c) {
    for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
      Cell<Dim> n, back;
      const std::int64_t x = std::int64_t(c.anchor[face_axis(f)]) + (face_side(f) ? 1 : -1) * std::int64_t(length(c));
      const bool inside = x >= 0 && x < std::int64_t(root_length<Dim>);
      RC_ASSERT(face_neighbour(c, f, n) == inside);
      if (!inside) continue;
      RC_ASSERT(is_valid(n));
      RC_ASSERT(n.level == c.level);
      RC_ASSERT(face_neighbour(n, f ^ 1, back));
      RC_ASSERT(back == c);
      Direction<Dim> dir{};
      dir[face_axis(f)] = face_side(f) ? 1 : -1;
      Cell<Dim> m;
      RC_ASSERT(neighbour(c, dir, m));
      RC_ASSERT(m == n);
    }
  });
  test::prop("corners are on the box, touches and is_corner agree", 200, [](const Cell<Dim>& c) {
    for (int k = 0; k < Cube<Dim>::n_corners; ++k) {
      const auto p = corner(c, k);
      RC_ASSERT(is_corner(c, p));
      RC_ASSERT(touches(c, p));
    }
    if (c.level < max_level<Dim>) {
      // The centre touches but is no corner.
      LatticePoint<Dim> mid;
      for (int d = 0; d < Dim; ++d) mid[d] = c.anchor[d] + length(c) / 2;
      RC_ASSERT(touches(c, mid));
      RC_ASSERT(!is_corner(c, mid));
    }
  });
}
