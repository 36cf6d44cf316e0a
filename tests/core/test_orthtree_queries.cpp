// Tests for the tree queries in core/orthtree.hpp: location, neighbours, box queries and lattice
// nodes, each against brute force over all leaves.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/cell_arbitrary.hpp"
#include "core/orthtree.hpp"
#include "property.hpp"

using namespace febemesh;

namespace {

template <int Dim> bool contains_half_open(const Cell<Dim>& c, const LatticePoint<Dim>& p) {
  for (int d = 0; d < Dim; ++d) {
    if (p[d] < c.anchor[d] || std::uint64_t(p[d]) >= std::uint64_t(c.anchor[d]) + length(c)) return false;
  }
  return true;
}

template <int Dim> std::size_t locate_brute(const Orthtree<Dim>& t, const LatticePoint<Dim>& p) {
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    if (contains_half_open(t.leaf(i), p)) return i;
  }
  return no_leaf;
}

/// Leaves sharing a (Dim-1)-dimensional part of facet f of leaf i, by brute force.
template <int Dim> std::vector<std::size_t> face_neighbours_brute(const Orthtree<Dim>& t, std::size_t i, int f) {
  const Cell<Dim>& c = t.leaf(i);
  const int axis = face_axis(f);
  const std::uint64_t plane = std::uint64_t(c.anchor[axis]) + (face_side(f) ? length(c) : 0);
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < t.n_leaves(); ++j) {
    const Cell<Dim>& n = t.leaf(j);
    const std::uint64_t their = std::uint64_t(n.anchor[axis]) + (face_side(f) ? 0 : length(n));
    if (their != plane) continue;
    bool overlap = true;
    for (int d = 0; d < Dim; ++d) {
      if (d == axis) continue;
      const std::uint64_t lo = std::max<std::uint64_t>(c.anchor[d], n.anchor[d]);
      const std::uint64_t hi = std::min<std::uint64_t>(std::uint64_t(c.anchor[d]) + length(c),
                                                       std::uint64_t(n.anchor[d]) + length(n));
      overlap = overlap && lo < hi;
    }
    if (overlap) out.push_back(j);
  }
  return out;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("locate by hand", "[orthtree][queries]", ((int Dim), Dim), 2, 3) {
  Box<Dim> domain{Point<Dim>::Constant(-2.0), Point<Dim>::Constant(2.0)};
  const auto t = refine(Orthtree<Dim>(domain), Flags{1});
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(-2.0))) == 0);
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(-1.0))) == 0);
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(0.0))) == t.n_leaves() - 1);  // lower-closed cells
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(2.0))) == t.n_leaves() - 1);  // upper root face
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(2.5))) == no_leaf);
  REQUIRE(locate(t, Point<Dim>(Point<Dim>::Constant(std::nan("")))) == no_leaf);
  Point<Dim> x = Point<Dim>::Constant(-1.0);
  x[0] = 1.0;
  REQUIRE(locate(t, x) == 1);
  LatticePoint<Dim> p{};
  REQUIRE(locate(t, p) == 0);
  p.fill(root_length<Dim>);
  REQUIRE(locate(t, p) == no_leaf);  // lattice cells are half-open
  REQUIRE(find_covering_leaf(t, Cell<Dim>{}) == no_leaf);
  REQUIRE(find_covering_leaf(t, child(child(Cell<Dim>{}, 1), 0)) == 1);
  REQUIRE(face_neighbours(t, 0, 0).empty());
  REQUIRE(face_neighbours(t, 0, 1) == std::vector<std::size_t>{1});
}

TEMPLATE_TEST_CASE_SIG("queries agree with brute force", "[orthtree][queries][property]", ((int Dim), Dim), 2, 3) {
  test::prop("locate and find_covering_leaf", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    for (int k = 0; k < 20; ++k) {
      const auto raw = *rc::gen::arbitrary<std::array<std::uint32_t, Dim>>();
      LatticePoint<Dim> p;
      for (int d = 0; d < Dim; ++d) p[d] = raw[d] % root_length<Dim>;
      const std::size_t j = locate(t, p);
      RC_ASSERT(j == locate_brute(t, p));
      RC_ASSERT(locate(t, position(t, p)) == j);
      const Cell<Dim> c = *test::gen_cell<Dim>(8);
      std::size_t brute = no_leaf;
      for (std::size_t i = 0; i < t.n_leaves(); ++i) {
        if (t.leaf(i) == c || is_ancestor(t.leaf(i), c)) brute = i;
      }
      RC_ASSERT(find_covering_leaf(t, c) == brute);
    }
  });
  test::prop("face neighbours: brute force, Morton order, symmetry", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
        const auto ns = face_neighbours(t, i, f);
        RC_ASSERT(ns == face_neighbours_brute(t, i, f));  // brute force is in index order
        for (const std::size_t j : ns) {
          const auto back = face_neighbours(t, j, f ^ 1);
          RC_ASSERT(std::find(back.begin(), back.end(), i) != back.end());
        }
      }
    }
  });
  test::prop("LeafKeys: the same answers as the tree queries, from any hint", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    const LeafKeys<Dim> keys(t);
    std::vector<std::size_t> out;
    for (int k = 0; k < 20; ++k) {
      const auto raw = *rc::gen::arbitrary<std::array<std::uint32_t, Dim>>();
      LatticePoint<Dim> p;
      for (int d = 0; d < Dim; ++d) p[d] = raw[d] % root_length<Dim>;
      const std::size_t hint = *rc::gen::inRange<std::size_t>(0, t.n_leaves() + 2);
      RC_ASSERT(keys.locate(p) == locate(t, p));
      RC_ASSERT(keys.locate_near(p, hint) == locate(t, p));
      const Cell<Dim> c = *test::gen_cell<Dim>(8);
      RC_ASSERT(keys.find_covering_leaf(c) == find_covering_leaf(t, c));
    }
    for (std::size_t i = 0; i < t.n_leaves(); ++i)
      for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
        keys.face_neighbours(i, f, out);
        RC_ASSERT(out == face_neighbours(t, i, f));
      }
  });
  test::prop("leaves_in_box", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    Box<Dim> b;
    for (int d = 0; d < Dim; ++d) {
      const double u = *rc::gen::inRange(0, 1001) / 1000.0, v = *rc::gen::inRange(0, 1001) / 1000.0;
      b.lo[d] = std::min(u, v) - 0.1;
      b.hi[d] = std::max(u, v);
    }
    std::vector<std::size_t> brute;
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      if (geometry(t, t.leaf(i)).overlaps(b)) brute.push_back(i);
    }
    RC_ASSERT(leaves_in_box(t, b) == brute);
  });
  test::prop("leaves_in_box, small boxes on and near cell sides", 100, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    Box<Dim> b;
    const double size = std::ldexp(1.0, -*rc::gen::inRange(0, 12));
    for (int d = 0; d < Dim; ++d) {
      const double u = *rc::gen::inRange(-2, 1027) / 1024.0;  // on the lattice of level 10, or just off it
      b.lo[d] = u - *rc::gen::inRange(0, 2) * 1e-12;
      b.hi[d] = b.lo[d] + *rc::gen::inRange(0, 2) * size;
    }
    std::vector<std::size_t> brute;
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      if (geometry(t, t.leaf(i)).overlaps(b)) brute.push_back(i);
    }
    RC_ASSERT(leaves_in_box(t, b) == brute);
  });
}

TEMPLATE_TEST_CASE_SIG("lattice nodes of a uniform tree", "[orthtree][nodes]", ((int Dim), Dim), 2, 3) {
  RefineOptions opt;
  opt.max_level = 3;
  const auto t = refine_while<Dim>(Orthtree<Dim>(), [](const Cell<Dim>&) { return true; }, opt);
  const auto nodes = lattice_nodes(t);
  std::size_t expected = 1;
  for (int d = 0; d < Dim; ++d) expected *= 9;
  REQUIRE(nodes.points.size() == expected);
  REQUIRE(std::count(nodes.hanging.begin(), nodes.hanging.end(), 1) == 0);
  // Keep only leaf 0: its corners, and -1 rows elsewhere.
  Flags keep(t.n_leaves(), 0);
  keep[0] = 1;
  const auto one = lattice_nodes(t, &keep);
  REQUIRE(one.points.size() == std::size_t(Cube<Dim>::n_corners));
  REQUIRE(one.leaf_corners[1][0] == -1);
  for (int k = 0; k < Cube<Dim>::n_corners; ++k) {
    REQUIRE(one.leaf_corners[0][k] == k);  // the corners of a cell are in Morton order already
    REQUIRE(one.find(corner(t.leaf(0), k)) == k);
  }
  REQUIRE(one.find(corner(t.leaf(1), Cube<Dim>::n_corners - 1)) == -1);
}

TEMPLATE_TEST_CASE_SIG("lattice nodes agree with brute force", "[orthtree][nodes][property]", ((int Dim), Dim), 2, 3) {
  test::prop("nodes are unique, sorted, found, and hanging exactly when they should", 50, [] {
    const auto t0 = (*test::gen_recipe<Dim>()).build();
    const bool balanced = *rc::gen::arbitrary<bool>();
    const auto t = balanced ? balance_2to1(t0) : t0;
    Flags keep(t.n_leaves());
    const int keep_percent = *rc::gen::element(100, 70);
    for (std::size_t i = 0; i < t.n_leaves(); ++i) keep[i] = test::mix64(i * 31 + 7) % 100 < std::uint64_t(keep_percent);
    const auto nodes = lattice_nodes(t, &keep);
    RC_ASSERT(nodes.points.size() == nodes.hanging.size());
    for (std::size_t n = 1; n < nodes.points.size(); ++n) {
      RC_ASSERT(point_key<Dim>(nodes.points[n - 1]) < point_key<Dim>(nodes.points[n]));
    }
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      for (int k = 0; k < Cube<Dim>::n_corners; ++k) {
        if (!keep[i]) {
          RC_ASSERT(nodes.leaf_corners[i][k] == -1);
          continue;
        }
        const std::int32_t n = nodes.leaf_corners[i][k];
        RC_ASSERT(n >= 0);
        RC_ASSERT(nodes.points[std::size_t(n)] == corner(t.leaf(i), k));
        RC_ASSERT(nodes.find(corner(t.leaf(i), k)) == n);
      }
    }
    for (std::size_t n = 0; n < nodes.points.size(); ++n) {
      const auto& p = nodes.points[n];
      bool hanging = false, used = false;
      for (std::size_t i = 0; i < t.n_leaves(); ++i) {
        if (!keep[i]) continue;
        used = used || is_corner(t.leaf(i), p);
        hanging = hanging || (touches(t.leaf(i), p) && !is_corner(t.leaf(i), p));
      }
      RC_ASSERT(used);
      RC_ASSERT(bool(nodes.hanging[n]) == hanging);
    }
  });
}

namespace {

/// Euler characteristic of the cell complex a tree forms: vertices are the lattice nodes, edges
/// the leaf edges cut at every node lying on them, facets (3D) the leaf facets whose neighbour
/// across is the same size or coarser (finer neighbours contribute their own smaller facets,
/// which tile the coarse one), and the leaves. Hanging nodes split edges, so the complex is
/// regular and a tree over the root cube gives V - E + F - C = 1 (2D: V - E + F = 1).
template <int Dim> long euler_characteristic(const Orthtree<Dim>& t) {
  const auto nodes = lattice_nodes(t);
  // Nodes on each axis-parallel lattice line: key (axis, the other coordinates) -> sorted
  // coordinates along the axis.
  std::map<std::pair<int, LatticePoint<Dim>>, std::vector<std::uint32_t>> lines;
  for (const auto& p : nodes.points) {
    for (int a = 0; a < Dim; ++a) {
      LatticePoint<Dim> rest = p;
      rest[a] = 0;
      lines[{a, rest}].push_back(p[a]);
    }
  }
  for (auto& [key, v] : lines) std::sort(v.begin(), v.end());
  std::set<std::pair<std::pair<int, LatticePoint<Dim>>, std::uint32_t>> segments;  // (line, start)
  std::set<std::pair<int, LatticePoint<Dim>>> facets;  // (axis of the normal, lower corner)
  for (const auto& c : t.leaves()) {
    const std::uint32_t len = length(c);
    for (int k = 0; k < Cube<Dim>::n_corners; ++k) {
      const LatticePoint<Dim> p = corner(c, k);
      for (int a = 0; a < Dim; ++a) {
        if (corner_is_upper(k, a)) continue;  // each edge once, from its lower end
        LatticePoint<Dim> rest = p;
        rest[a] = 0;
        const auto& v = lines.at({a, rest});
        auto it = std::lower_bound(v.begin(), v.end(), p[a]);
        for (; it + 1 != v.end() && *(it + 1) <= p[a] + len; ++it) segments.insert({{a, rest}, *it});
      }
    }
    if constexpr (Dim == 3) {
      for (int f = 0; f < Cube<Dim>::n_faces; ++f) {
        Cell<Dim> across;
        if (face_neighbour(c, f, across) && find_covering_leaf(t, across) == no_leaf) continue;  // finer
        LatticePoint<Dim> lo = c.anchor;
        if (face_side(f)) lo[face_axis(f)] += len;
        facets.insert({face_axis(f), lo});
      }
    }
  }
  const long V = long(nodes.points.size()), E = long(segments.size()), C = long(t.n_leaves());
  return Dim == 2 ? V - E + C : V - E + long(facets.size()) - C;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("lattice nodes satisfy Euler's formula", "[orthtree][nodes]", ((int Dim), Dim), 2, 3) {
  const Orthtree<Dim> root;
  REQUIRE(euler_characteristic(root) == 1);
  // One corner child split: hanging nodes on the shared facets (and, in 3D, facet centres).
  const auto t = refine(refine(root, Flags{1}), [] {
    Flags f(Cube<Dim>::n_children, 0);
    f[0] = 1;
    return f;
  }());
  REQUIRE(euler_characteristic(t) == 1);
  // The sum counts every piece: a leaf missing from C would change it.
  const long uniform = euler_characteristic(refine(refine(root, Flags{1}), Flags(Cube<Dim>::n_children, 1)));
  REQUIRE(uniform == 1);
}

TEMPLATE_TEST_CASE_SIG("lattice nodes satisfy Euler's formula on random trees", "[orthtree][nodes][property]",
                       ((int Dim), Dim), 2, 3) {
  test::prop("V - E + F (- C) = 1, hanging nodes splitting edges", 50, [] {
    const auto t0 = (*test::gen_recipe<Dim>()).build();
    const auto t = *rc::gen::arbitrary<bool>() ? balance_2to1(t0) : t0;
    RC_ASSERT(euler_characteristic(t) == 1);
  });
}
