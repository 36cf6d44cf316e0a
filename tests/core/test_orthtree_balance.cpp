// Tests for the tree invariants and 2:1 balance in core/orthtree.hpp. The balance is compared
// with the textbook ripple algorithm (split any leaf with a neighbour two levels finer, repeat
// until nothing changes), whose every split is forced, so it yields the coarsest balanced tree.

#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "core/cell_arbitrary.hpp"
#include "core/error.hpp"
#include "core/orthtree.hpp"
#include "property.hpp"

using namespace febemesh;

namespace {

/// Dimension of the intersection of two closed lattice boxes, -1 if apart.
template <int Dim> int contact(const Cell<Dim>& a, const Cell<Dim>& b) {
  int dim = 0;
  for (int d = 0; d < Dim; ++d) {
    const std::uint64_t lo = std::max<std::uint64_t>(a.anchor[d], b.anchor[d]);
    const std::uint64_t hi = std::min<std::uint64_t>(std::uint64_t(a.anchor[d]) + length(a),
                                                     std::uint64_t(b.anchor[d]) + length(b));
    if (lo > hi) return -1;
    if (lo < hi) ++dim;
  }
  return dim;
}

template <int Dim> Orthtree<Dim> ripple_balance(Orthtree<Dim> t, BalanceKind kind) {
  const int needed = kind == BalanceKind::Face ? Dim - 1 : 0;
  for (;;) {
    Flags flags(t.n_leaves(), 0);
    bool any = false;
    for (std::size_t i = 0; i < t.n_leaves(); ++i) {
      for (std::size_t j = 0; j < t.n_leaves() && !flags[i]; ++j) {
        const int k = contact(t.leaf(i), t.leaf(j));
        if (k >= needed && k < Dim && t.leaf(j).level > t.leaf(i).level + 1) flags[i] = 1;
      }
      any = any || flags[i];
    }
    if (!any) return t;
    t = refine(t, flags);
  }
}

template <int Dim> bool refines(const Orthtree<Dim>& fine, const Orthtree<Dim>& coarse) {
  for (const auto& c : fine.leaves()) {
    if (find_covering_leaf(coarse, c) == no_leaf) return false;
  }
  return true;
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("invariants catch broken trees", "[orthtree][invariants]", ((int Dim), Dim), 2, 3) {
  const Orthtree<Dim> root;
  REQUIRE(is_complete(root));
  REQUIRE(is_complete_ref(root));
  const auto t = refine(refine(root, Flags{1}), Flags(Cube<Dim>::n_children, 0));
  REQUIRE(is_sorted_and_linear(t));
  // Built by hand without the constructor's Debug check: a tree missing a leaf, one with a
  // duplicate, one unsorted, one with an overlap.
  auto leaves = t.leaves();
  const auto check = [](const LeafVector<Dim>& cells, bool sorted_linear, bool complete) {
    // The constructor asserts completeness in Debug builds, so plant the broken leaves into a
    // (non-const) tree directly.
    Orthtree<Dim> tree;
    const_cast<LeafVector<Dim>&>(tree.leaves()) = cells;
    CHECK(is_sorted_and_linear(tree) == sorted_linear);
    CHECK(is_sorted_and_linear_ref(tree) == sorted_linear);
    CHECK(is_complete(tree) == complete);
    CHECK(is_complete_ref(tree) == complete);
  };
  check(leaves, true, true);
  auto missing = leaves;
  missing.erase(missing.begin() + 1);
  check(missing, true, false);
  auto duplicate = leaves;
  duplicate.insert(duplicate.begin() + 1, duplicate[1]);
  check(duplicate, false, false);
  auto unsorted = leaves;
  std::swap(unsorted[0], unsorted[1]);
  check(unsorted, false, false);
  auto overlap = leaves;
  overlap.insert(overlap.begin(), Cell<Dim>{});
  check(overlap, false, false);
  auto deeper = leaves;  // replace leaf 0 by its children: still complete
  const auto kids = children(deeper[0]);
  deeper.erase(deeper.begin());
  deeper.insert(deeper.begin(), kids.begin(), kids.end());
  check(deeper, true, true);
}

TEMPLATE_TEST_CASE_SIG("balance: a deep cell at the centre", "[orthtree][balance]", ((int Dim), Dim), 2, 3) {
  // Refine toward the centre from the upper quadrant down to level 5: the level-5 cells at the
  // centre touch the level-1 cells of the other quadrants.
  RefineOptions opt;
  opt.max_level = 5;
  const auto t = refine_while<Dim>(Orthtree<Dim>(), [](const Cell<Dim>& c) {
    for (int d = 0; d < Dim; ++d) {
      if (c.level > 0 && c.anchor[d] != root_length<Dim> / 2) return false;
    }
    return true;
  }, opt);
  REQUIRE(t.n_leaves() == std::size_t(1 + 5 * (Cube<Dim>::n_children - 1)));
  for (const auto kind : {BalanceKind::Face, BalanceKind::Full}) {
    REQUIRE_FALSE(is_balanced(t, kind));
    REQUIRE_FALSE(is_balanced_ref(t, kind));
    const auto b = balance_2to1(t, kind);
    REQUIRE(b.n_leaves() > t.n_leaves());
    REQUIRE(is_complete(b));
    REQUIRE(is_balanced(b, kind));
    REQUIRE(is_balanced_ref(b, kind));
    REQUIRE(b.leaves() == ripple_balance(t, kind).leaves());
  }
  // Full balance also splits the level-1 cell that touches the centre only at a corner (2D) or
  // along an edge (3D): strictly more leaves than face balance.
  REQUIRE(balance_2to1(t, BalanceKind::Full).n_leaves() > balance_2to1(t, BalanceKind::Face).n_leaves());
  // The corner chain toward the origin is already balanced (each ring touches the next only).
  const auto chain = refine_while<Dim>(Orthtree<Dim>(), [](const Cell<Dim>& c) { return morton_key(c) == 0; }, opt);
  REQUIRE(is_balanced(chain, BalanceKind::Full));
  REQUIRE(balance_2to1(chain, BalanceKind::Full).leaves() == chain.leaves());
}

TEMPLATE_TEST_CASE_SIG("balance properties on random trees", "[orthtree][balance][property]", ((int Dim), Dim), 2, 3) {
  test::prop("random refinement gives sorted, complete trees; fast invariants equal slow ones", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    RC_ASSERT(is_sorted_and_linear(t));
    RC_ASSERT(is_sorted_and_linear_ref(t));
    RC_ASSERT(is_complete(t));
    RC_ASSERT(is_complete_ref(t));
    for (const auto kind : {BalanceKind::Face, BalanceKind::Full}) {
      RC_ASSERT(is_balanced(t, kind) == is_balanced_ref(t, kind));
    }
  });
  test::prop("balance_2to1 is the coarsest balanced refinement, idempotent", 60, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    for (const auto kind : {BalanceKind::Face, BalanceKind::Full}) {
      const auto b = balance_2to1(t, kind);
      RC_ASSERT(is_complete(b));
      RC_ASSERT(is_balanced(b, kind));
      RC_ASSERT(is_balanced_ref(b, kind));
      RC_ASSERT(refines(b, t));
      RC_ASSERT(balance_2to1(b, kind).leaves() == b.leaves());
      RC_ASSERT(b.leaves() == ripple_balance(t, kind).leaves());
      if (kind == BalanceKind::Full) RC_ASSERT(is_balanced(b, BalanceKind::Face));
    }
  });
}

TEMPLATE_TEST_CASE_SIG("balance refuses results beyond the leaf limit", "[orthtree][balance][limits]", ((int Dim), Dim), 2, 3) {
  // A chain of cells down to level 10 around a point off the coarse lattice: its neighbours
  // across the parents' facets are coarser, so the balance adds leaves at every level.
  RefineOptions ro;
  ro.max_level = 10;
  LatticePoint<Dim> p;
  p.fill(root_length<Dim> / 3);
  const auto t = refine_while<Dim>(Orthtree<Dim>(), [p](const Cell<Dim>& c) { return touches(c, p); }, ro);
  const auto full = balance_2to1(t);
  REQUIRE(full.n_leaves() > t.n_leaves());
  // Exactly the size of the result passes; one less is refused, naming the count and memory.
  BalanceOptions opt;
  opt.max_leaves = full.n_leaves();
  REQUIRE(balance_2to1(t, BalanceKind::Face, opt).leaves() == full.leaves());
  opt.max_leaves = full.n_leaves() - 1;
  try {
    (void)balance_2to1(t, BalanceKind::Face, opt);
    FAIL("expected LimitError");
  } catch (const LimitError& e) {
    const std::string msg = e.what();
    INFO(msg);
    REQUIRE(msg.find("max_leaves = " + std::to_string(opt.max_leaves)) != std::string::npos);
    REQUIRE(msg.find("MiB") != std::string::npos);
    REQUIRE(msg.find(std::to_string(full.n_leaves())) != std::string::npos);
  }
  // An input already beyond the limit is refused before any work.
  opt.max_leaves = t.n_leaves() - 1;
  REQUIRE_THROWS_AS(balance_2to1(t, BalanceKind::Full, opt), LimitError);
}

TEMPLATE_TEST_CASE_SIG("parallel balance equals serial", "[orthtree][balance]", ((int Dim), Dim), 2, 3) {
  // A band of fine cells around a sphere, graded by nothing: large enough that every level's
  // candidates are cut into pieces (4096 or more internal cells) and the final walk is cut
  // into many subtrees at a split level below the root.
  const double r = 0.35;
  const int k = Dim == 2 ? 12 : 7;
  const ControlFn<Dim> control = [=](const Box<Dim>& b) {  // [=]: clang warns on an explicit capture of the constant k
    const Point<Dim> c = Point<Dim>::Constant(0.5);
    const double near = (c.cwiseMax(b.lo).cwiseMin(b.hi) - c).norm();
    Point<Dim> far;
    for (int d = 0; d < Dim; ++d) far[d] = std::max(std::abs(b.lo[d] - c[d]), std::abs(b.hi[d] - c[d]));
    return near <= r && far.norm() >= r ? double(k) : 0.0;
  };
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto t = subdivide_by_control<Dim>(unit, control);
  REQUIRE(t.n_leaves() > 20000);
  for (const auto kind : {BalanceKind::Face, BalanceKind::Full}) {
    const auto serial = balance_2to1(t, kind);
    REQUIRE(serial.n_leaves() > t.n_leaves());
    REQUIRE(is_complete(serial));
    REQUIRE(is_balanced(serial, kind));
    REQUIRE(serial.leaves().capacity() == serial.n_leaves());
    for (const int threads : {2, 3, 4}) {
      BalanceOptions opt;
      opt.n_threads = threads;
      INFO("threads " << threads);
      REQUIRE(balance_2to1(t, kind, opt).leaves() == serial.leaves());
    }
  }
  // The limit holds on several threads too.
  BalanceOptions opt;
  opt.n_threads = 2;
  opt.max_leaves = balance_2to1(t).n_leaves() - 1;
  REQUIRE_THROWS_AS(balance_2to1(t, BalanceKind::Face, opt), LimitError);
}

TEMPLATE_TEST_CASE_SIG("parallel balance equals serial on random trees", "[orthtree][balance][property]", ((int Dim), Dim), 2, 3) {
  test::prop("balance_2to1 with 2 and 3 threads", 40, [] {
    const auto t = (*test::gen_recipe<Dim>()).build();
    for (const auto kind : {BalanceKind::Face, BalanceKind::Full}) {
      const auto serial = balance_2to1(t, kind);
      for (const int threads : {2, 3}) {
        BalanceOptions opt;
        opt.n_threads = threads;
        RC_ASSERT(balance_2to1(t, kind, opt).leaves() == serial.leaves());
      }
    }
  });
}
