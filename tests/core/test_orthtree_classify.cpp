// Tests for classify() in core/orthtree.hpp against analytic circles, spheres and boxes.

#include <catch2/catch.hpp>

#include "core/analytic_boundaries.hpp"
#include "core/orthtree.hpp"
#include "property.hpp"

using namespace febemesh;

namespace {

/// Checks the classification of every leaf against the analytic inside test at its corners.
template <int Dim>
void check_sides(const Orthtree<Dim>& t, const Boundary<Dim>& b, const std::vector<Side>& sides) {
  REQUIRE(sides.size() == t.n_leaves());
  for (std::size_t i = 0; i < t.n_leaves(); ++i) {
    const Box<Dim> box = geometry(t, t.leaf(i));
    int inside = 0;
    for (int k = 0; k < Cube<Dim>::n_corners; ++k) inside += b.is_inside(position(t, corner(t.leaf(i), k))) ? 1 : 0;
    if (sides[i] == Side::In) {
      // The solids are convex: all corners strictly inside means the closed cell is strictly
      // inside, so it does not touch the boundary.
      REQUIRE(inside == Cube<Dim>::n_corners);
      REQUIRE(b.is_inside(box.center()));
    } else if (sides[i] == Side::Out) {
      REQUIRE(inside == 0);
    }
  }
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("classification of analytic solids", "[orthtree][classify]", ((int Dim), Dim), 2, 3) {
  const Box<Dim> domain{Point<Dim>::Constant(-1.0), Point<Dim>::Constant(1.0)};
  const test::Ball<Dim> ball(Point<Dim>::Constant(0.05), 0.7, Dim == 2 ? 7 : 5);
  const test::BoxSolid<Dim> solid(Box<Dim>{Point<Dim>::Constant(-0.6), Point<Dim>::Constant(0.3)}, Dim == 2 ? 7 : 5);
  const std::vector<const Boundary<Dim>*> solids{&ball, &solid};
  for (const Boundary<Dim>* b : solids) {
    const auto tree = balance_2to1(subdivide_by_control<Dim>(domain, [b](const Box<Dim>& box) { return b->control_level(box); }));
    const auto sides = classify(tree, *b);
    check_sides(tree, *b, sides);
    REQUIRE(std::count(sides.begin(), sides.end(), Side::In) > 0);
    REQUIRE(std::count(sides.begin(), sides.end(), Side::Out) > 0);
    REQUIRE(std::count(sides.begin(), sides.end(), Side::Partial) > 0);
    REQUIRE(classify(tree, *b, 2) == sides);
    REQUIRE(classify(tree, *b, 3) == sides);
    REQUIRE(classify_ref(tree, *b) == sides);
    // The paper's refinement puts the boundary in the finest cells: every PARTIAL leaf is at the
    // requested level.
    for (std::size_t i = 0; i < tree.n_leaves(); ++i) {
      if (sides[i] == Side::Partial) REQUIRE(tree.leaf(i).level == (Dim == 2 ? 7 : 5));
    }
  }
}

TEMPLATE_TEST_CASE_SIG("classification on random balls", "[orthtree][classify][property]", ((int Dim), Dim), 2, 3) {
  test::prop("IN cells inside, OUT cells outside, threads agree", 40, [] {
    Point<Dim> c;
    for (int d = 0; d < Dim; ++d) c[d] = *rc::gen::inRange(-500, 501) / 1000.0;
    const double r = *rc::gen::inRange(50, 900) / 1000.0;
    const test::Ball<Dim> ball(c, r, Dim == 2 ? 6 : 4);
    const Box<Dim> domain{Point<Dim>::Constant(-1.0), Point<Dim>::Constant(1.0)};
    const auto tree = subdivide_by_control<Dim>(domain, [&](const Box<Dim>& box) { return ball.control_level(box); });
    const auto sides = classify(tree, ball, 1);
    for (std::size_t i = 0; i < tree.n_leaves(); ++i) {
      const Box<Dim> box = geometry(tree, tree.leaf(i));
      int inside = 0;
      for (int k = 0; k < Cube<Dim>::n_corners; ++k) inside += ball.is_inside(position(tree, corner(tree.leaf(i), k))) ? 1 : 0;
      if (sides[i] == Side::In) {
        RC_ASSERT(inside == Cube<Dim>::n_corners);
        RC_ASSERT(ball.farthest_distance(box) < r);
      }
      if (sides[i] == Side::Out) {
        RC_ASSERT(inside == 0);
        RC_ASSERT(ball.nearest_distance(box) > r);
      }
    }
    RC_ASSERT(classify(tree, ball, 2) == sides);
    RC_ASSERT(classify_ref(tree, ball) == sides);
  });
}

TEMPLATE_TEST_CASE_SIG("classifying a refined tree from the answers before it", "[orthtree][classify][property]",
                       ((int Dim), Dim), 2, 3) {
  test::prop("classify_refined is classify", 40, [] {
    Point<Dim> c;
    for (int d = 0; d < Dim; ++d) c[d] = *rc::gen::inRange(-500, 501) / 1000.0;
    const double r = *rc::gen::inRange(50, 900) / 1000.0;
    const test::Ball<Dim> ball(c, r, Dim == 2 ? 6 : 4);
    const Box<Dim> domain{Point<Dim>::Constant(-1.0), Point<Dim>::Constant(1.0)};
    const auto before = subdivide_by_control<Dim>(domain, [&](const Box<Dim>& box) { return ball.control_level(box); });
    const auto before_sides = classify(before, ball, 1);
    // A repair's refinement: some leaves (IN, OUT and Partial ones) split, then 2:1 balance.
    const auto pick = *rc::gen::container<std::vector<bool>>(*rc::gen::inRange(1, 17), rc::gen::arbitrary<bool>());
    Flags flags(before.n_leaves(), 0);
    std::size_t n_split = 0;
    for (std::size_t i = 0; i < before.n_leaves(); ++i)
      if (pick[i % pick.size()] && before.leaf(i).level < (Dim == 2 ? 9 : 6)) flags[i] = 1, ++n_split;
    RC_PRE(n_split > 0);
    const auto after = balance_2to1(refine(before, flags), BalanceKind::Full);
    const auto expected = classify(after, ball, 1);
    const int n_threads = *rc::gen::inRange(1, 4);
    RC_ASSERT(classify_refined(after, before, before_sides, ball, n_threads) == expected);
    // Not a refinement (coarser leaves): classified from scratch, the same answers.
    RC_ASSERT(classify_refined(before, after, expected, ball, n_threads) == before_sides);
    // Answers that do not fit the tree before: from scratch too.
    RC_ASSERT(classify_refined(after, before, std::vector<Side>{}, ball, n_threads) == expected);
  });
}
