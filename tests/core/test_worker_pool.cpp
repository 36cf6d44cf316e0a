#include <catch2/catch.hpp>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel_ranges.hpp"
#include "core/worker_pool.hpp"

using namespace febemesh;

TEST_CASE("run_on_threads runs every t once, each on a thread of its own, t = 0 on the caller", "[worker_pool][threads]") {
  for (const int n : {1, 2, 3, 5}) {
    INFO(n << " threads");
    std::mutex m;
    std::vector<int> runs(static_cast<std::size_t>(n), 0);
    std::set<std::thread::id> ids;
    std::thread::id zero;
    run_on_threads(n, [&](int t) {
      const std::lock_guard<std::mutex> hold(m);
      ++runs[static_cast<std::size_t>(t)];
      ids.insert(std::this_thread::get_id());
      if (t == 0) zero = std::this_thread::get_id();
    });
    CHECK(runs == std::vector<int>(static_cast<std::size_t>(n), 1));
    CHECK(ids.size() == static_cast<std::size_t>(n));
    CHECK(zero == std::this_thread::get_id());
  }
}

TEST_CASE("run_on_threads' threads run at the same time: one t may wait for another", "[worker_pool][threads]") {
  // Each t waits until every t has arrived (the sweeps' threads wait for each other's nodes).
  for (int call = 0; call < 200; ++call) {
    std::atomic<int> arrived{0};
    run_on_threads(3, [&](int) {
      arrived.fetch_add(1);
      while (arrived.load() < 3) std::this_thread::yield();
    });
    REQUIRE(arrived.load() == 3);
  }
}

TEST_CASE("run_on_threads keeps its threads from call to call", "[worker_pool][threads]") {
  run_on_threads(3, [](int) {});
  const int started = pool_threads_started();
  CHECK(started >= 2);
  std::atomic<long> sum{0};
  for (int call = 0; call < 1000; ++call) run_on_threads(3, [&](int t) { sum.fetch_add(t); });
  CHECK(sum.load() == 3000);
  CHECK(pool_threads_started() == started);  // (a thread a call before: 2000 of them)
}

TEST_CASE("run_on_threads rethrows the lowest thread's exception after all have returned", "[worker_pool][threads]") {
  std::atomic<int> returned{0};
  try {
    run_on_threads(4, [&](int t) {
      if (t == 3) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // still running when 1 throws
        returned.fetch_add(1);
        throw std::runtime_error("three");
      }
      if (t == 1) throw std::runtime_error("one");
      returned.fetch_add(1);
    });
    FAIL("no exception");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()) == "one");
  }
  CHECK(returned.load() == 3);  // t = 0, 2 and 3 ran to their end before the rethrow
  // The pool works after it.
  std::atomic<int> n{0};
  run_on_threads(4, [&](int) { n.fetch_add(1); });
  CHECK(n.load() == 4);
}

TEST_CASE("run_on_threads nested in a call, and from two threads at once, gives every call its threads", "[worker_pool][threads]") {
  // Nested: the pool is busy, so the inner call starts threads of its own.
  std::atomic<int> inner{0};
  run_on_threads(2, [&](int) { run_on_threads(3, [&](int) { inner.fetch_add(1); }); });
  CHECK(inner.load() == 6);
  // Two callers at once (the CLI writes mesh.msh while it measures the fidelity): the same
  // sums as one after the other.
  std::vector<long> totals(2, 0);
  std::vector<std::thread> callers;
  for (int c = 0; c < 2; ++c)
    callers.emplace_back([&, c] {
      for (int call = 0; call < 300; ++call) {
        std::vector<long> part(4, 0);
        for_each_range(4000, 4, [&](std::size_t begin, std::size_t end) {
          long s = 0;
          for (std::size_t i = begin; i < end; ++i) s += static_cast<long>(i);
          part[begin / 1000] = s;
        });
        for (const long s : part) totals[static_cast<std::size_t>(c)] += s;
      }
    });
  for (std::thread& th : callers) th.join();
  const long once = 4000L * 3999L / 2;
  CHECK(totals[0] == 300 * once);
  CHECK(totals[1] == 300 * once);
}
