// core/ordered_sweep.hpp: the DAG of an in-order sweep links each node to its neighbours in the
// sweep; visit_dag visits each node once, after its earlier neighbours; an in-order Gauss-Seidel
// sweep gives the serial numbers, bit for bit, on any thread count.

#include <catch2/catch.hpp>
#include <rapidcheck.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/ordered_sweep.hpp"
#include "property.hpp"
#include "sweep_relaxation.hpp"

using namespace febemesh;

namespace {

/// A symmetric graph as adjacency lists.
struct Graph {
  std::vector<std::vector<std::int32_t>> adj;
  std::size_t size() const { return adj.size(); }
  void link(std::int32_t a, std::int32_t b) {
    adj[static_cast<std::size_t>(a)].push_back(b);
    adj[static_cast<std::size_t>(b)].push_back(a);
  }
  auto neighbours() const {
    return [this](std::int32_t v, auto&& visit) {
      for (const std::int32_t u : adj[static_cast<std::size_t>(v)]) visit(u);
    };
  }
};

/// n nodes, each linked to a few others by a deterministic generator (loops and repeats too).
Graph random_graph(std::size_t n, unsigned seed, int links_per_node) {
  Graph g;
  g.adj.resize(n);
  std::uint64_t s = seed * 0x9E3779B97F4A7C15ULL + 1;
  const auto rnd = [&] {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<std::size_t>(s >> 33);
  };
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < links_per_node; ++k) {
      // Mostly near neighbours (as in a mesh), now and then a far one.
      const std::size_t u = rnd() % 8 == 0 ? rnd() % n : std::min(n - 1, v + rnd() % 40);
      g.link(static_cast<std::int32_t>(v), static_cast<std::int32_t>(u));
    }
  return g;
}

/// Every other node, and every node of the first quarter: a sweep over part of the graph.
std::vector<std::int32_t> some_nodes(std::size_t n) {
  std::vector<std::int32_t> nodes;
  for (std::size_t v = 0; v < n; ++v)
    if (v % 2 == 0 || v < n / 4) nodes.push_back(static_cast<std::int32_t>(v));
  return nodes;
}

/// Checks the DAG's contract: the sweep's nodes in order; position i's later neighbours are
/// exactly its neighbours after it in the sweep, ascending; n_earlier counts those before it.
void check_dag(const Graph& g, const std::vector<std::int32_t>& nodes, const SweepDag& d) {
  REQUIRE(d.node == nodes);
  std::vector<std::int32_t> position(g.size(), -1);
  for (std::size_t i = 0; i < nodes.size(); ++i) position[static_cast<std::size_t>(nodes[i])] = static_cast<std::int32_t>(i);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    std::vector<std::int32_t> later, earlier;
    for (const std::int32_t u : g.adj[static_cast<std::size_t>(nodes[i])]) {
      const std::int32_t j = position[static_cast<std::size_t>(u)];
      if (j > static_cast<std::int32_t>(i)) later.push_back(j);
      if (j >= 0 && j < static_cast<std::int32_t>(i)) earlier.push_back(j);
    }
    std::sort(later.begin(), later.end());
    later.erase(std::unique(later.begin(), later.end()), later.end());
    std::sort(earlier.begin(), earlier.end());
    earlier.erase(std::unique(earlier.begin(), earlier.end()), earlier.end());
    const auto got = d.later(i);
    REQUIRE(std::vector<std::int32_t>(got.begin(), got.end()) == later);
    REQUIRE(d.n_earlier[i] == static_cast<std::int32_t>(earlier.size()));
  }
}

}  // namespace

TEST_CASE("sweep_dag of a path and of a star", "[ordered_sweep]") {
  Graph path;
  path.adj.resize(5);
  for (std::int32_t v = 0; v + 1 < 5; ++v) path.link(v, v + 1);
  const std::vector<std::int32_t> all{0, 1, 2, 3, 4};
  const SweepDag p = sweep_dag(5, all, path.neighbours());
  check_dag(path, all, p);
  CHECK(p.n_earlier == std::vector<std::int32_t>{0, 1, 1, 1, 1});  // a chain
  const std::vector<std::int32_t> even{0, 2, 4};  // no two of them neighbours: no edges
  CHECK(sweep_dag(5, even, path.neighbours()).next.empty());

  Graph star;
  star.adj.resize(6);
  for (std::int32_t v = 1; v < 6; ++v) star.link(0, v), star.link(v, 0);  // repeated edges
  const std::vector<std::int32_t> six{0, 1, 2, 3, 4, 5};
  const SweepDag s = sweep_dag(6, six, star.neighbours());
  check_dag(star, six, s);
  CHECK(s.later(0).size() == 5);  // the hub, then all the leaves at once
  CHECK(s.n_earlier == std::vector<std::int32_t>{0, 1, 1, 1, 1, 1});
  CHECK(sweep_dag(6, {}, star.neighbours()).size() == 0);
}

TEST_CASE("sweep_dag links each node to its neighbours in the sweep", "[ordered_sweep][property]") {
  febemesh::test::prop("the DAG follows the order", 60, [](unsigned seed) {
    const auto n = static_cast<std::size_t>(*rc::gen::inRange(1, 400));
    const int links = *rc::gen::inRange(0, 6);
    const Graph g = random_graph(n, seed, links);
    const std::vector<std::int32_t> nodes = some_nodes(n);
    check_dag(g, nodes, sweep_dag(n, nodes, g.neighbours()));
    const int threads = *rc::gen::inRange(2, 5);
    check_dag(g, nodes, sweep_dag(n, nodes, g.neighbours(), threads));  // built in parts
    // Lists ascending and distinct (as a mesh's neighbour lists come: sweep_dag takes them as
    // they are), and ascending with repeats (sorted again).
    Graph sorted = g, repeated = g;
    for (std::size_t v = 0; v < n; ++v) {
      std::vector<std::int32_t>& a = sorted.adj[v];
      std::sort(a.begin(), a.end());
      a.erase(std::unique(a.begin(), a.end()), a.end());
      repeated.adj[v].clear();
      for (const std::int32_t u : a) repeated.adj[v].insert(repeated.adj[v].end(), {u, u});
    }
    check_dag(sorted, nodes, sweep_dag(n, nodes, sorted.neighbours(), threads));
    check_dag(repeated, nodes, sweep_dag(n, nodes, repeated.neighbours(), threads));
  });
}

TEST_CASE("visit_dag visits every node once, after its earlier neighbours", "[ordered_sweep]") {
  const Graph g = random_graph(5000, 3, 3);
  const std::vector<std::int32_t> nodes = some_nodes(g.size());
  const SweepDag d = sweep_dag(g.size(), nodes, g.neighbours());
  for (const int threads : {1, 2, 3, 4}) {
    std::vector<std::atomic<int>> count(g.size());
    std::vector<std::int64_t> begin(g.size(), -1), end(g.size(), -1);
    std::atomic<std::int64_t> clock{0};
    std::atomic<int> bad_thread{0};
    visit_dag(d, threads, [&](std::int32_t v, int t) {
      if (t < 0 || t >= threads) ++bad_thread;
      begin[static_cast<std::size_t>(v)] = clock++;
      ++count[static_cast<std::size_t>(v)];
      end[static_cast<std::size_t>(v)] = clock++;
    });
    CAPTURE(threads);
    CHECK(bad_thread == 0);
    for (std::size_t v = 0; v < g.size(); ++v) {
      const bool in_sweep = std::binary_search(nodes.begin(), nodes.end(), static_cast<std::int32_t>(v));
      REQUIRE(count[v] == (in_sweep ? 1 : 0));
    }
    for (const std::int32_t v : nodes)
      for (const std::int32_t u : g.adj[static_cast<std::size_t>(v)])
        if (u < v && std::binary_search(nodes.begin(), nodes.end(), u))
          REQUIRE(end[static_cast<std::size_t>(u)] < begin[static_cast<std::size_t>(v)]);
  }
}

TEST_CASE("an in-order sweep gives the serial numbers on any thread count", "[ordered_sweep]") {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const Graph g = random_graph(6000, seed, 4);
    const std::vector<std::int32_t> nodes = some_nodes(g.size());
    test::Relaxation serial(g.adj);
    for (int it = 0; it < 5; ++it)
      for (const std::int32_t v : nodes) serial.visit(v);
    for (const int threads : {1, 2, 3, 4}) {
      const OrderedSweep sweep(nodes, g.size(), threads, g.neighbours(), 0);
      CHECK(sweep.n_threads() == threads);
      CHECK(sweep.size() == nodes.size());
      test::Relaxation r(g.adj);
      for (int it = 0; it < 5; ++it) sweep.run([&](std::int32_t v, int) { r.visit(v); });
      CAPTURE(seed, threads);
      CHECK(r.x == serial.x);  // bit for bit
      CHECK(r.settled == serial.settled);
    }
  }
  // Few nodes: no DAG, the caller's thread alone.
  const Graph g = random_graph(100, 1, 2);
  CHECK(OrderedSweep(some_nodes(100), 100, 2, g.neighbours()).n_threads() == 1);
}

TEST_CASE("an exception in a visit reaches the caller after all threads stopped", "[ordered_sweep]") {
  const Graph g = random_graph(3000, 5, 2);
  std::vector<std::int32_t> nodes(g.size());
  for (std::size_t v = 0; v < g.size(); ++v) nodes[v] = static_cast<std::int32_t>(v);
  for (const int threads : {1, 2, 3}) {
    const OrderedSweep sweep(nodes, g.size(), threads, g.neighbours(), 0);
    const auto visit = [&](std::int32_t v, int) {
      if (v == 1234) throw std::runtime_error("node 1234");
    };
    CHECK_THROWS_WITH(sweep.run(visit), "node 1234");
  }
}
