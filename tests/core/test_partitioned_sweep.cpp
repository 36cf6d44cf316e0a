// core/partitioned_sweep.hpp: slabs of about equal node counts, ordered along the first axis;
// separators are exactly the nodes of elements across slabs; inner nodes of two slabs share no
// element; a partitioned Gauss-Seidel sweep gives the numbers of its order, bit for bit, on any
// thread count; exceptions reach the caller.

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

#include "core/partitioned_sweep.hpp"
#include "sweep_relaxation.hpp"
#include "test_mesh_fixtures.hpp"

using namespace febemesh;

namespace {

/// A triangle grid of n x n cells, its nodes moved off the lattice a little (deterministically)
/// and its node ids shuffled by a fixed permutation, so that ids say nothing of positions.
Mesh<2> jittered_grid(int n) {
  Mesh<2> m = test::grid_mesh<2>(n, true);
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    const double t = static_cast<double>(v);
    m.points[v] += 0.3 * Point<2>(std::sin(1.7 * t), std::cos(2.3 * t));
  }
  const std::size_t nn = m.points.size();
  std::vector<std::int32_t> to(nn);
  for (std::size_t v = 0; v < nn; ++v) to[v] = static_cast<std::int32_t>((v * 7919) % nn);  // 7919 prime, coprime with nn
  std::vector<Point<2>> moved(nn);
  for (std::size_t v = 0; v < nn; ++v) moved[static_cast<std::size_t>(to[v])] = m.points[v];
  m.points = moved;
  for (VertexId& id : m.solid.node) id.v = to[static_cast<std::size_t>(id.v)];
  return m;
}

/// The nodes that share an element with each node (itself excluded), ascending.
std::vector<std::vector<std::int32_t>> element_neighbours(const Mesh<2>& m) {
  std::vector<std::set<std::int32_t>> s(m.points.size());
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    const int k = m.solid.n_nodes_of(ElemId{static_cast<std::int32_t>(e)});
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        if (i != j) s[static_cast<std::size_t>(v[i].v)].insert(v[j].v);
  }
  std::vector<std::vector<std::int32_t>> out(s.size());
  for (std::size_t v = 0; v < s.size(); ++v) out[v].assign(s[v].begin(), s[v].end());
  return out;
}


}  // namespace

TEST_CASE("slab_parts: slabs of about equal counts, in order along x, the same on any thread count", "[partitioned_sweep]") {
  const Mesh<2> m = jittered_grid(120);  // 14,641 nodes
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, 16, 1);
  REQUIRE(part.size() == m.points.size());
  std::vector<std::size_t> count(16, 0);
  double hi_before = -1e300;
  for (int p = 0; p < 16; ++p) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t v = 0; v < part.size(); ++v)
      if (part[v] == p) ++count[static_cast<std::size_t>(p)], lo = std::min(lo, m.points[v][0]), hi = std::max(hi, m.points[v][0]);
    CAPTURE(p);
    CHECK(lo > hi_before);  // slab p lies to the right of slab p - 1
    hi_before = hi;
  }
  // Cut at the edges of 256 bins: each slab within a bin or two of n / 16 on this near-uniform grid.
  for (const std::size_t c : count) CHECK(std::abs(static_cast<double>(c) - part.size() / 16.0) < 2.5 * part.size() / 256.0);
  for (const int threads : {2, 3, 4}) CHECK(slab_parts<2>(m.points, 16, threads) == part);
  // One part, a flat range, no points: all in part 0.
  CHECK(slab_parts<2>(m.points, 1, 2) == std::vector<std::uint8_t>(part.size(), 0));
  CHECK(slab_parts<2>(std::vector<Point<2>>(50, Point<2>(1.0, 2.0)), 16, 1) == std::vector<std::uint8_t>(50, 0));
  CHECK(slab_parts<2>(std::vector<Point<2>>{}, 16, 1).empty());
}

TEST_CASE("separators are the nodes of elements across slabs; inner nodes of two slabs share no element", "[partitioned_sweep]") {
  const Mesh<2> m = jittered_grid(60);
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, 4, 1);  // slabs 15 columns wide
  const std::vector<std::uint8_t> sep = separators(part, m.solid, 1);
  std::vector<std::uint8_t> expected(m.points.size(), 0);
  std::size_t inner_pairs_checked = 0;
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    std::set<std::uint8_t> parts;
    for (int i = 0; i < 3; ++i) parts.insert(part[static_cast<std::size_t>(v[i].v)]);
    if (parts.size() > 1)
      for (int i = 0; i < 3; ++i) expected[static_cast<std::size_t>(v[i].v)] = 1;
  }
  CHECK(sep == expected);
  for (std::size_t e = 0; e < m.solid.size(); ++e) {
    const VertexId* v = m.solid.nodes(ElemId{static_cast<std::int32_t>(e)});
    std::set<std::uint8_t> inner_parts;
    for (int i = 0; i < 3; ++i)
      if (!sep[static_cast<std::size_t>(v[i].v)]) inner_parts.insert(part[static_cast<std::size_t>(v[i].v)]);
    CHECK(inner_parts.size() <= 1);
    inner_pairs_checked += inner_parts.size();
  }
  CHECK(inner_pairs_checked > m.solid.size() / 2);  // most elements have inner nodes
  const std::size_t n_sep = static_cast<std::size_t>(std::count(sep.begin(), sep.end(), 1));
  CHECK(n_sep > 0);
  CHECK(n_sep < m.points.size() / 3);
  for (const int threads : {2, 3}) CHECK(separators(part, m.solid, threads) == sep);
}

TEST_CASE("a partitioned sweep's order: each slab's inner nodes ascending, then the separators", "[partitioned_sweep]") {
  const Mesh<2> m = jittered_grid(40);
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, 8, 1);
  const std::vector<std::uint8_t> sep = separators(part, m.solid, 1);
  const auto keep = [](std::int32_t v) { return v % 5 != 0; };
  const PartitionedSweep sweep(part, 8, sep, keep, 2);
  CHECK(sweep.n_parts() == 8);
  std::vector<std::int32_t> expected;
  for (int p = 0; p < 8; ++p)
    for (std::size_t v = 0; v < part.size(); ++v)
      if (part[v] == p && !sep[v] && keep(static_cast<std::int32_t>(v))) expected.push_back(static_cast<std::int32_t>(v));
  std::size_t n_sep = 0;
  for (std::size_t v = 0; v < part.size(); ++v)
    if (sep[v] && keep(static_cast<std::int32_t>(v))) expected.push_back(static_cast<std::int32_t>(v)), ++n_sep;
  const auto order = sweep.order();
  CHECK(std::vector<std::int32_t>(order.begin(), order.end()) == expected);
  CHECK(sweep.n_separators() == n_sep);
}

TEST_CASE("a partitioned sweep gives its order's numbers on any thread count", "[partitioned_sweep]") {
  for (const int n : {30, 90}) {
    const Mesh<2> m = jittered_grid(n);
    const auto nb = element_neighbours(m);
    const std::vector<std::uint8_t> part = slab_parts<2>(m.points, default_sweep_parts, 1);
    const std::vector<std::uint8_t> sep = separators(part, m.solid, 1);
    const auto keep = [](std::int32_t v) { return v % 7 != 3; };
    test::Relaxation serial(nb);
    {
      const PartitionedSweep one(part, default_sweep_parts, sep, keep, 1);
      for (int it = 0; it < 5; ++it)
        for (const std::int32_t v : one.order()) serial.visit(v);
    }
    for (const int threads : {1, 2, 3, 4}) {
      const PartitionedSweep sweep(part, default_sweep_parts, sep, keep, threads);
      CHECK(sweep.n_threads() == threads);
      test::Relaxation r(nb);
      std::vector<std::size_t> visits(nb.size(), 0);
      std::size_t betweens = 0;
      for (int it = 0; it < 5; ++it)
        sweep.run(
            [&](std::int32_t v, int t) {
              REQUIRE(t >= 0);
              REQUIRE(t < threads);
              ++visits[static_cast<std::size_t>(v)];  // (each node by one thread a sweep)
              r.visit(v);
            },
            [&] { ++betweens; });
      CAPTURE(n, threads);
      CHECK(r.x == serial.x);  // bit for bit
      CHECK(r.settled == serial.settled);
      CHECK(betweens == 5);
      for (std::size_t v = 0; v < nb.size(); ++v) REQUIRE(visits[v] == (keep(static_cast<std::int32_t>(v)) ? 5u : 0u));
      // skip: the skipped nodes are not visited, the others as before.
      std::atomic<std::size_t> visited = 0;  // (counted from every thread)
      sweep.run([&](std::int32_t, int) { ++visited; }, [] {}, [](std::int32_t v) { return v % 2 == 0; });
      std::size_t odd_kept = 0;
      for (const std::int32_t v : sweep.order()) odd_kept += v % 2 != 0;
      CHECK(visited.load() == odd_kept);
    }
  }
}

TEST_CASE("an exception in a partitioned sweep reaches the caller after all threads stopped", "[partitioned_sweep]") {
  const Mesh<2> m = jittered_grid(40);
  const std::vector<std::uint8_t> part = slab_parts<2>(m.points, 16, 1);
  const PartitionedSweep probe(part, 16, separators(part, m.solid, 1), [](std::int32_t) { return true; }, 1);
  // An inner node of some slab and a separator: a throw from either stops the sweep.
  const std::int32_t inner = probe.order().front(), separator = probe.order().back();
  for (const std::int32_t bad : {inner, separator})
    for (const int threads : {1, 2, 3}) {
      const PartitionedSweep sweep(part, 16, separators(part, m.solid, 1), [](std::int32_t) { return true; }, threads);
      CAPTURE(bad, threads);
      CHECK_THROWS_WITH(sweep.run([&](std::int32_t v, int) {
        if (v == bad) throw std::runtime_error("bad node");
      }),
                        "bad node");
    }
}
