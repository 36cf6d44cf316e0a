// Tests for core/free_facets.hpp: the incremental update against a fresh computation.

#include <catch2/catch.hpp>

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
