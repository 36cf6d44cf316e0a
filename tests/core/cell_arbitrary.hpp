#pragma once
// rapidcheck generators for the tree: arbitrary valid cells, and random trees built from a random
// refinement predicate (a hashed coin per cell plus deep refinement around random points, so that
// trees are often far from balanced).

#include <cstdint>
#include <vector>

#include <rapidcheck.h>

#include "core/orthtree.hpp"

namespace febemesh::test {

inline std::uint64_t mix64(std::uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// A valid cell whose level is at most `deepest`.
template <int Dim> rc::Gen<Cell<Dim>> gen_cell(int deepest = max_level<Dim>) {
  return rc::gen::apply(
      [](int level, std::array<std::uint32_t, Dim> raw) {
        Cell<Dim> c;
        c.level = std::uint8_t(level);
        const std::uint32_t len = std::uint32_t(1) << (max_level<Dim> - level);
        for (int d = 0; d < Dim; ++d) c.anchor[d] = raw[d] & (root_length<Dim> - 1) & ~(len - 1);
        return c;
      },
      rc::gen::inRange(0, deepest + 1), rc::gen::arbitrary<std::array<std::uint32_t, Dim>>());
}

/// The parameters of a random refinement predicate.
template <int Dim> struct TreeRecipe {
  std::uint64_t seed = 0;
  int coin_percent = 0;  ///< chance to split a shallow cell
  int coin_depth = 0;    ///< coin flips only below this level
  int point_depth = 0;   ///< cells holding a seed point are split down to this level
  std::vector<LatticePoint<Dim>> points;

  bool wants_split(const Cell<Dim>& c) const {
    if (c.level < coin_depth &&
        mix64(morton_key(c) ^ (std::uint64_t(c.level) << 58) ^ seed) % 100 < std::uint64_t(coin_percent)) {
      return true;
    }
    if (c.level >= point_depth) return false;
    for (const auto& p : points) {
      if (touches(c, p)) return true;
    }
    return false;
  }
  Orthtree<Dim> build() const {
    RefineOptions opt;
    opt.max_level = std::max(coin_depth, point_depth);
    return refine_while(Orthtree<Dim>(), std::function<bool(const Cell<Dim>&)>([this](const Cell<Dim>& c) {
                          return wants_split(c);
                        }),
                        opt);
  }
};

/// Small random trees: at most a few thousand leaves, levels up to 9 (2D) / 6 (3D).
template <int Dim> rc::Gen<TreeRecipe<Dim>> gen_recipe() {
  constexpr int deep = Dim == 2 ? 9 : 6;
  constexpr int coin_depth = Dim == 2 ? 5 : 3;
  return rc::gen::apply(
      [](std::uint64_t seed, int percent, int point_depth, std::vector<std::array<std::uint32_t, Dim>> raw) {
        TreeRecipe<Dim> r;
        r.seed = seed;
        r.coin_percent = percent;
        r.coin_depth = coin_depth;
        r.point_depth = point_depth;
        for (const auto& q : raw) {
          LatticePoint<Dim> p;
          for (int d = 0; d < Dim; ++d) p[d] = q[d] % (root_length<Dim> + 1);
          r.points.push_back(p);
        }
        return r;
      },
      rc::gen::arbitrary<std::uint64_t>(), rc::gen::inRange(0, 60), rc::gen::inRange(0, deep + 1),
      rc::gen::mapcat(rc::gen::inRange<std::size_t>(0, 4), [](std::size_t n) {
        return rc::gen::container<std::vector<std::array<std::uint32_t, Dim>>>(
            n, rc::gen::arbitrary<std::array<std::uint32_t, Dim>>());
      }));
}

}  // namespace febemesh::test

namespace rc {
template <int Dim> struct Arbitrary<febemesh::Cell<Dim>> {
  static Gen<febemesh::Cell<Dim>> arbitrary() { return febemesh::test::gen_cell<Dim>(); }
};
}  // namespace rc
