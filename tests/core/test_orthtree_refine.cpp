// Tests for refinement in core/orthtree.hpp: the paper's rule, flags, predicates, limits, threads.

#include <catch2/catch.hpp>

#include <map>

#include "core/cell_arbitrary.hpp"
#include "core/error.hpp"
#include "core/orthtree.hpp"
#include "property.hpp"

using namespace febemesh;

namespace {

template <int Dim> std::map<int, int> level_histogram(const Orthtree<Dim>& t) {
  std::map<int, int> h;
  for (const auto& c : t.leaves()) ++h[c.level];
  return h;
}

/// Control parameter 3 in every box that holds `p`, 0 elsewhere.
template <int Dim> ControlFn<Dim> point_control(const Point<Dim>& p, double level) {
  return [p, level](const Box<Dim>& b) { return b.contains(p) ? level : 0.0; };
}

}  // namespace

TEMPLATE_TEST_CASE_SIG("the paper's check_and_subdivide_quadrant by hand", "[orthtree][refine]", ((int Dim), Dim), 2, 3) {
  // Control 3 at p = (0.1, ...). Root (L=0): 3 > 1, split and check. The child holding p (L=1):
  // 3 > 2, split and check; its siblings: 0 <= 2, split once and stop (level-2 leaves). The
  // level-2 cells under p's child: 3 > 3 fails, so each is split once: level-3 leaves.
  constexpr int nc = Cube<Dim>::n_children;
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto t = subdivide_by_control<Dim>(unit, point_control<Dim>(Point<Dim>::Constant(0.1), 3.0));
  REQUIRE(is_complete(t));
  const auto h = level_histogram(t);
  REQUIRE(h.size() == 2);
  REQUIRE(h.at(2) == (nc - 1) * nc);
  REQUIRE(h.at(3) == nc * nc);
  REQUIRE(t.n_leaves() == std::size_t((nc - 1) * nc + nc * nc));
  // The first leaves are the level-3 cells of the first level-2 cell, in child order.
  for (int i = 0; i < nc; ++i) {
    REQUIRE(t.leaf(i) == child(child(child(Cell<Dim>{}, 0), 0), i));
  }
  // Control 0 everywhere: the root is still split once (rule b).
  const auto flat = subdivide_by_control<Dim>(unit, [](const Box<Dim>&) { return 0.0; });
  REQUIRE(flat.n_leaves() == std::size_t(nc));
  // Control exactly L+1 at the root does not recurse.
  const auto one = subdivide_by_control<Dim>(unit, [](const Box<Dim>&) { return 1.0; });
  REQUIRE(one.n_leaves() == std::size_t(nc));
  // Uniform control k gives the uniform tree of level k (the last split is rule b).
  const auto uniform = subdivide_by_control<Dim>(unit, [](const Box<Dim>&) { return 3.0; });
  REQUIRE(uniform.n_leaves() == std::size_t(nc * nc * nc));
}

TEST_CASE("the paper's rule in 2D, leaf list by hand", "[orthtree][refine]") {
  // Control 2.5 near the origin: root splits and checks (2.5 > 1); the lower-left child checks
  // 2.5 > 2 and splits with its children checked; those (L=2) have 2.5 <= 3 and split once.
  const Box<2> unit{Point<2>(0, 0), Point<2>(1, 1)};
  const auto t = subdivide_by_control<2>(unit, point_control<2>(Point<2>(0.01, 0.01), 2.5));
  // Level 2 under child 0 of the root: four cells; only the one holding the point is checked,
  // but all level-2 cells are split once: 16 level-3 leaves; other root children: 12 level-2.
  REQUIRE(t.n_leaves() == 28);
  const std::uint32_t q = root_length<2> / 4, e = root_length<2> / 8;
  // Leaf 0..3: children of the level-2 cell at the origin.
  REQUIRE(t.leaf(0) == Cell<2>{{0, 0}, 3});
  REQUIRE(t.leaf(1) == Cell<2>{{e, 0}, 3});
  REQUIRE(t.leaf(2) == Cell<2>{{0, e}, 3});
  REQUIRE(t.leaf(3) == Cell<2>{{e, e}, 3});
  REQUIRE(t.leaf(4) == Cell<2>{{q, 0}, 3});
  REQUIRE(t.leaf(16) == Cell<2>{{2 * q, 0}, 2});
  REQUIRE(t.leaf(27) == Cell<2>{{3 * q, 3 * q}, 2});
}

TEMPLATE_TEST_CASE_SIG("subdivision respects the level cap and the leaf budget", "[orthtree][refine]", ((int Dim), Dim), 2, 3) {
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto deep = [](const Box<Dim>&) { return 1000.0; };
  RefineOptions opt;
  opt.max_level = 2;
  const auto t = subdivide_by_control<Dim>(unit, deep, opt);
  REQUIRE(t.n_leaves() == std::size_t(1) << (2 * Dim));
  opt.max_level = 0;
  REQUIRE(subdivide_by_control<Dim>(unit, deep, opt).n_leaves() == 1);

  // A uniform request far beyond the budget is refused early with an estimate.
  opt.max_level = -1;
  opt.max_leaves = 10000;
  for (const int threads : {1, 2}) {
    opt.n_threads = threads;
    try {
      (void)subdivide_by_control<Dim>(unit, [](const Box<Dim>&) { return 12.0; }, opt);
      FAIL("expected LimitError");
    } catch (const LimitError& e) {
      const std::string msg = e.what();
      INFO(msg);
      REQUIRE(msg.find("max_leaves = 10000") != std::string::npos);
      REQUIRE(msg.find("MiB") != std::string::npos);
      // Uniform level 12: the serial estimate is exact, 2^(12 Dim) leaves (threads report
      // their counts and volumes at slightly different moments).
      if (threads == 1) REQUIRE(msg.find(std::to_string(std::uint64_t(1) << (12 * Dim))) != std::string::npos);
    }
  }
  opt.max_level = max_level<Dim> + 1;
  REQUIRE_THROWS_AS(subdivide_by_control<Dim>(unit, deep, opt), LimitError);
  // A domain of no size is bad input.
  REQUIRE_THROWS_AS(subdivide_by_control<Dim>(Box<Dim>{}, deep), InputError);
}

TEMPLATE_TEST_CASE_SIG("subdivision maps a non-cubic domain onto a cube", "[orthtree][refine]", ((int Dim), Dim), 2, 3) {
  Box<Dim> domain{Point<Dim>::Constant(-1.0), Point<Dim>::Constant(1.0)};
  domain.hi[0] = 3.0;
  const auto t = subdivide_by_control<Dim>(domain, [](const Box<Dim>&) { return 0.0; });
  REQUIRE(t.root_box().lo == domain.lo);
  REQUIRE(t.root_box().hi == Point<Dim>::Constant(3.0));
  REQUIRE(t.unit() == 4.0 / double(root_length<Dim>));
  const Box<Dim> last = geometry(t, t.leaves().back());
  REQUIRE(last.hi == t.root_box().hi);
  REQUIRE(last.lo == Point<Dim>::Constant(1.0));
}

TEMPLATE_TEST_CASE_SIG("mark, refine and refine_while", "[orthtree][refine]", ((int Dim), Dim), 2, 3) {
  const Orthtree<Dim> root;
  REQUIRE(root.n_leaves() == 1);
  const auto t1 = refine(root, Flags{1});
  REQUIRE(t1.n_leaves() == std::size_t(Cube<Dim>::n_children));
  const Flags flags = mark<Dim>(t1, [](const Cell<Dim>& c) { return child_id(c) == 0; });
  REQUIRE(std::count(flags.begin(), flags.end(), 1) == 1);
  const auto t2 = refine(t1, flags);
  REQUIRE(t2.n_leaves() == std::size_t(2 * Cube<Dim>::n_children - 1));
  REQUIRE(is_complete(t2));
  REQUIRE(t2.leaf(0).level == 2);
  REQUIRE_THROWS_AS(refine(t2, Flags{1}), InputError);

  // Refine toward the origin corner down to level 5.
  RefineOptions opt;
  opt.max_level = 5;
  const auto t3 = refine_while<Dim>(root, [](const Cell<Dim>& c) { return morton_key(c) == 0; }, opt);
  REQUIRE(t3.n_leaves() == std::size_t(1 + 5 * (Cube<Dim>::n_children - 1)));
  REQUIRE(t3.leaf(0).level == 5);
  opt.max_leaves = 10;
  REQUIRE_THROWS_AS(refine_while<Dim>(root, [](const Cell<Dim>&) { return true; }, opt), LimitError);
}

TEMPLATE_TEST_CASE_SIG("large refinements span many storage blocks, threads agree", "[orthtree][refine]", ((int Dim), Dim), 2, 3) {
  // Uniform level 10 (2D, 1Mi leaves) or 7 (3D, 2Mi leaves): several of the spool's blocks
  // (256 Ki leaves each) per thread, drained in order into the tree.
  constexpr int level = Dim == 2 ? 10 : 7;
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto control = [](const Box<Dim>&) { return double(level); };
  RefineOptions opt;
  const auto serial = subdivide_by_control<Dim>(unit, control, opt);
  REQUIRE(serial.n_leaves() == std::size_t(1) << (Dim * level));
  REQUIRE(is_complete(serial));
  REQUIRE(serial.leaves().capacity() == serial.n_leaves());
  for (std::size_t i = 0; i < serial.n_leaves(); ++i) {
    if (serial.leaf(i) != cell_from_key<Dim>(std::uint64_t(i) << (Dim * (max_level<Dim> - level)), level)) {
      FAIL("leaf " << i << " is not the i-th cell of the uniform grid");
    }
  }
  for (const int threads : {2, 3}) {
    opt.n_threads = threads;
    REQUIRE(subdivide_by_control<Dim>(unit, control, opt).leaves() == serial.leaves());
    REQUIRE(refine_while<Dim>(Orthtree<Dim>(), [](const Cell<Dim>& c) { return c.level < level; }, opt).leaves() ==
            serial.leaves());
  }
}

TEMPLATE_TEST_CASE_SIG("parallel refinement equals serial", "[orthtree][refine][property]", ((int Dim), Dim), 2, 3) {
  test::prop("subdivide_by_control with 1, 2 and 3 threads", 30, [] {
    // A ball-shaped control: level k near a sphere of random radius, lower elsewhere.
    const double r = *rc::gen::inRange(10, 45) / 100.0;
    const int k = *rc::gen::inRange(2, Dim == 2 ? 10 : 6);
    const ControlFn<Dim> control = [r, k](const Box<Dim>& b) {
      const Point<Dim> c = Point<Dim>::Constant(0.5);
      const double near = (c.cwiseMax(b.lo).cwiseMin(b.hi) - c).norm();
      Point<Dim> far;
      for (int d = 0; d < Dim; ++d) far[d] = std::max(std::abs(b.lo[d] - c[d]), std::abs(b.hi[d] - c[d]));
      return near <= r && far.norm() >= r ? double(k) : 1.0;
    };
    const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
    RefineOptions opt;
    const auto serial = subdivide_by_control<Dim>(unit, control, opt);
    RC_ASSERT(is_complete(serial));
    for (const int threads : {2, 3}) {
      opt.n_threads = threads;
      RC_ASSERT(subdivide_by_control<Dim>(unit, control, opt).leaves() == serial.leaves());
    }
  });
  test::prop("refine_while with 1 and 2 threads", 30, [] {
    const auto recipe = *test::gen_recipe<Dim>();
    const auto base = recipe.build();
    RefineOptions opt;
    opt.max_level = recipe.coin_depth + 2;
    const std::function<bool(const Cell<Dim>&)> pred = [&](const Cell<Dim>& c) {
      return test::mix64(morton_key(c) + c.level) % 3 == 0;
    };
    const auto serial = refine_while<Dim>(base, pred, opt);
    opt.n_threads = 2;
    RC_ASSERT(refine_while<Dim>(base, pred, opt).leaves() == serial.leaves());
  });
}
