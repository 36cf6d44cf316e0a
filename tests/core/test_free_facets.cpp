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
