// Tests for core/free_facets.hpp: the incremental update against a fresh computation.

#include <catch2/catch.hpp>

#include <utility>

#include "core/free_facets.hpp"
#include "core/cell_arbitrary.hpp"
#include "property.hpp"

using namespace febemesh;

namespace {

template <int Dim> bool same(const std::vector<FreeFacet<Dim>>& a, const std::vector<FreeFacet<Dim>>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].leaf != b[k].leaf || a[k].face != b[k].face || a[k].cell.anchor != b[k].cell.anchor ||
        a[k].cell.level != b[k].cell.level)
      return false;
  return true;
}

/// The unit cube in 4^Dim leaves of size 0.25, the lower half along axis 0 kept (x < 0.5).
template <int Dim> struct HalfKept {
  Orthtree<Dim> t;
  Flags keep;
  HalfKept() {
    for (int k = 0; k < 2; ++k) t = refine(t, Flags(t.n_leaves(), 1));
    keep.resize(t.n_leaves());
    for (std::size_t i = 0; i < t.n_leaves(); ++i) keep[i] = geometry(t, t.leaf(i)).center()[0] < 0.5 ? 1 : 0;
  }
  /// The segment along y from 0.05 to 0.95 on the plane x = `x` (0.3 in the other coordinates).
  static std::pair<Point<Dim>, Point<Dim>> along_y(double x) {
    Point<Dim> a = Point<Dim>::Constant(0.3), b = a;
    a[0] = b[0] = x;
    a[1] = 0.05;
    b[1] = 0.95;
    return {a, b};
  }
};

}  // namespace

TEMPLATE_TEST_CASE_SIG("update_free_facets gives free_facets after the change", "[free_facets][property]", ((int Dim), Dim), 2,
                       3) {
  test::prop("dropping and adding leaves, a few at a time", 50, [] {
    const auto t = balance_2to1((*test::gen_recipe<Dim>()).build());
    Flags keep(t.n_leaves());
    const std::uint64_t salt = *rc::gen::inRange<std::uint64_t>(0, 1000);
    for (std::size_t i = 0; i < t.n_leaves(); ++i) keep[i] = test::mix64(i * 31 + salt) % 100 < 70;
    const LeafKeys<Dim> keys(t);
    std::vector<FreeFacet<Dim>> facets = free_facets(t, keys, keep);
    RC_ASSERT(same<Dim>(facets, free_facets(t, keep)));
    for (int round = 0; round < 3; ++round) {
      std::vector<std::size_t> changed;
      for (std::size_t i = 0; i < t.n_leaves(); ++i)
        if (test::mix64(i * 131 + salt * 7 + round) % 100 < 15) {
          keep[i] = !keep[i];
          changed.push_back(i);
        }
      update_free_facets(t, keys, keep, changed, facets);
      RC_ASSERT(same<Dim>(facets, free_facets(t, keep)));
    }
  });
}

TEMPLATE_TEST_CASE_SIG("free_facets skips only facets with kept leaves across", "[free_facets][property]", ((int Dim), Dim), 2,
                       3) {
  test::prop("against every leaf's facets searched", 50, [] {
    const auto t = balance_2to1((*test::gen_recipe<Dim>()).build());
    // Long runs of kept leaves (where the searches are skipped): those whose anchor lies in a
    // ball around a random lattice point, some of them dropped.
    const std::uint64_t salt = *rc::gen::inRange<std::uint64_t>(0, 1000);
    const double radius = double(*rc::gen::inRange<int>(1, 100)) / 100.0 * double(root_length<Dim>);
    Point<Dim> centre;
    for (int d = 0; d < Dim; ++d) centre[d] = double(test::mix64(salt + d) % root_length<Dim>);
    Flags keep(t.n_leaves());
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      Point<Dim> a;
      for (int d = 0; d < Dim; ++d) a[d] = double(t.leaf(i).anchor[d]);
      keep[i] = (a - centre).norm() < radius && test::mix64(i + salt) % 100 < 97;
    }
    const LeafKeys<Dim> keys(t);
    std::vector<std::size_t> all(t.n_leaves());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    std::vector<FreeFacet<Dim>> searched;
    update_free_facets(t, keys, keep, all, searched);  // every kept leaf's facets searched
    RC_ASSERT(same<Dim>(free_facets(t, keys, keep), searched));
  });
}

TEMPLATE_TEST_CASE_SIG("segment_enters_kept_region: the graze allowance only at the region's boundary", "[free_facets]",
                       ((int Dim), Dim), 2, 3) {
  const HalfKept<Dim> h;
  const Orthtree<Dim>& t = h.t;
  const Flags& keep = h.keep;
  // Along the plane x = 0.25 between two kept leaves, 0.01 (0.04 of a leaf) off it: the face
  // is inside the region, so the segment enters it; each leaf alone is only grazed.
  auto [a, b] = HalfKept<Dim>::along_y(0.26);
  CHECK_FALSE(segment_enters_kept(t, keep, a, b, 0.05));
  CHECK(segment_enters_kept_region(t, keep, a, b, 0.05));
  // Along the region's boundary x = 0.5, 0.01 inside: grazing, allowed by both; but it runs
  // along the leaves for more than half their size (graze_length 0.5).
  a[0] = b[0] = 0.49;
  CHECK_FALSE(segment_enters_kept(t, keep, a, b, 0.05));
  CHECK_FALSE(segment_enters_kept_region(t, keep, a, b, 0.05));
  CHECK(segment_enters_kept_region(t, keep, a, b, 0.05, 0.5));
  // Out of the region from 0.01 inside it: a short graze, allowed.
  Point<Dim> c = a;
  c[0] = 0.8;
  CHECK_FALSE(segment_enters_kept_region(t, keep, a, c, 0.05, 0.5));
  // Deeper than the allowance: refused by both.
  a[0] = b[0] = 0.4;
  CHECK(segment_enters_kept(t, keep, a, b, 0.05));
  CHECK(segment_enters_kept_region(t, keep, a, b, 0.05));
}

TEMPLATE_TEST_CASE_SIG("cells_along_kept: the run along the kept leaves in leaf sizes", "[free_facets]",
                       ((int Dim), Dim), 2, 3) {
  const HalfKept<Dim> h;
  const Orthtree<Dim>& t = h.t;
  const Flags& keep = h.keep;
  // On the region's boundary plane x = 0.5 from y 0.05 to 0.95: 0.9 = 3.6 leaf sizes along it.
  auto [a, b] = HalfKept<Dim>::along_y(0.5);
  CHECK(cells_along_kept(t, keep, a, b, 0.05) == Approx(3.6));
  // 0.1 outside it (0.4 of a leaf, more than the allowance): none.
  a[0] = b[0] = 0.6;
  CHECK(cells_along_kept(t, keep, a, b, 0.05) == 0.0);
  // Straight out of the region from its boundary: only the allowance's 0.0125.
  a[0] = b[0] = 0.5;
  b[1] = a[1];
  b[0] = 0.9;
  CHECK(cells_along_kept(t, keep, a, b, 0.05) == Approx(0.05));
}

TEMPLATE_TEST_CASE_SIG("free_facets gives the same list on any thread count", "[free_facets]", ((int Dim), Dim), 2, 3) {
  // Enough leaves for several runs of 2^14 on two threads (65,536 in 2D, 32,768 + in 3D), the
  // leaves near a corner refined once more and the tree balanced; kept: a ball whose runs of
  // kept keys cross the runs' ends, with some leaves dropped inside.
  Orthtree<Dim> t;
  for (int k = 0; k < (Dim == 2 ? 8 : 5); ++k) t = refine(t, Flags(t.n_leaves(), 1));
  Flags finer(t.n_leaves(), 0);
  for (std::size_t i = 0; i < t.n_leaves(); ++i) finer[i] = geometry(t, t.leaf(i)).center().norm() < 0.3 ? 1 : 0;
  t = balance_2to1(refine(t, finer));
  REQUIRE(t.n_leaves() > (std::size_t(1) << 15));
  Flags keep(t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i)
    keep[i] = (geometry(t, t.leaf(i)).center() - Point<Dim>::Constant(0.45)).norm() < 0.4 && test::mix64(i) % 100 < 98;
  const LeafKeys<Dim> keys(t);
  const std::vector<FreeFacet<Dim>> one = free_facets(t, keys, keep, 1);
  REQUIRE(one.size() > 100);
  // Against every kept leaf's facets searched (no runs at all).
  std::vector<std::size_t> all(t.n_leaves());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  std::vector<FreeFacet<Dim>> searched;
  update_free_facets(t, keys, keep, all, searched);
  CHECK(same<Dim>(one, searched));
  for (const int n_threads : {2, 3, 8}) {
    INFO(n_threads << " threads");
    CHECK(same<Dim>(free_facets(t, keys, keep, n_threads), one));
  }
}
