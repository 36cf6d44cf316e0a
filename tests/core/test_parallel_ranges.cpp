#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "core/parallel_ranges.hpp"

using namespace febemesh;

TEST_CASE("range_max is the serial maximum on any thread count", "[parallel_ranges][threads]") {
  std::vector<double> v(100003);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(0.37 * static_cast<double>(i)) * static_cast<double>(i % 977);
  v[4242] = std::numeric_limits<double>::quiet_NaN();  // never wins
  double serial = -std::numeric_limits<double>::infinity();
  for (const double x : v)
    if (!std::isnan(x)) serial = std::max(serial, x);
  for (const int threads : {1, 2, 3, 8}) {
    INFO(threads << " threads");
    CHECK(range_max(v.size(), threads, [&](std::size_t i) { return v[i]; }) == serial);
    CHECK(range_max(3, threads, [&](std::size_t i) { return v[i]; }) == std::max({v[0], v[1], v[2]}));
  }
  CHECK(range_max(0, 2, [](std::size_t) { return 1.0; }) == -std::numeric_limits<double>::infinity());
}

TEST_CASE("range_max and range_min run on as many threads as they are given", "[parallel_ranges][threads]") {
  // With one part a thread, for_each_range's rule (fewer than two items a worker: one thread)
  // ran every call on the caller alone.
  for (const int threads : {2, 3}) {
    std::mutex m;
    std::set<std::thread::id> seen;
    const auto f = [&](std::size_t i) {
      if (i % 1000 == 0) {
        const std::lock_guard<std::mutex> hold(m);
        seen.insert(std::this_thread::get_id());
      }
      return static_cast<double>(i);
    };
    CHECK(range_max(100000, threads, f) == 99999.0);
    CHECK(seen.size() == static_cast<std::size_t>(threads));
    seen.clear();
    CHECK(range_min(100000, threads, f) == 0.0);
    CHECK(seen.size() == static_cast<std::size_t>(threads));
  }
}

TEST_CASE("range_min is the serial minimum; chunk_starts is the serial layout", "[parallel_ranges][threads]") {
  std::vector<double> v(50001);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::cos(0.11 * static_cast<double>(i)) * static_cast<double>(i % 313);
  double serial = std::numeric_limits<double>::infinity();
  for (const double x : v) serial = std::min(serial, x);
  // Items per position: i % 5 (0 for some), laid out in order from 7.
  std::vector<std::size_t> serial_start{7};
  for (std::size_t i = 0; i < v.size(); ++i) serial_start.push_back(serial_start.back() + i % 5);
  for (const int threads : {1, 2, 3, 8}) {
    INFO(threads << " threads");
    CHECK(range_min(v.size(), threads, [&](std::size_t i) { return v[i]; }) == serial);
    const std::size_t chunk = chunk_size(v.size(), threads, 1000);
    CHECK(chunk >= 1000);
    const std::vector<std::size_t> start = chunk_starts(v.size(), chunk, threads, std::size_t{7}, [](std::size_t b, std::size_t e) {
      std::size_t k = 0;
      for (std::size_t i = b; i < e; ++i) k += i % 5;
      return k;
    });
    REQUIRE(start.size() == (v.size() + chunk - 1) / chunk + 1);
    for (std::size_t c = 0; c + 1 < start.size(); ++c) CHECK(start[c] == serial_start[c * chunk]);
    CHECK(start.back() == serial_start.back());
  }
  CHECK(range_min(0, 2, [](std::size_t) { return 1.0; }) == std::numeric_limits<double>::infinity());
  CHECK(chunk_starts(0, 16, 2, std::size_t{3}, [](std::size_t, std::size_t) { return std::size_t{1}; }) == std::vector<std::size_t>{3});
}

TEST_CASE("for_each_chunk runs every chunk once, a chunk a thread when there are as many", "[parallel_ranges][threads]") {
  for (const int threads : {1, 2, 3, 8})
    for (const std::size_t n_chunks : {std::size_t(1), std::size_t(2), std::size_t(3), std::size_t(7), std::size_t(40)}) {
      const std::size_t chunk = 5, n = chunk * n_chunks - 2;  // the last chunk is short
      std::vector<std::atomic<int>> runs(n_chunks);
      std::mutex m;
      std::set<std::thread::id> seen;
      for_each_chunk(n, chunk, threads, [&](std::size_t c, std::size_t begin, std::size_t end) {
        CHECK(begin == c * chunk);
        CHECK(end == std::min(n, (c + 1) * chunk));
        ++runs[c];
        const std::lock_guard<std::mutex> hold(m);
        seen.insert(std::this_thread::get_id());
      });
      CAPTURE(threads, n_chunks);
      for (const auto& r : runs) CHECK(r.load() == 1);
      // (For_each_range alone ran 2 and 3 chunks on one thread.)
      CHECK(seen.size() == std::min<std::size_t>(static_cast<std::size_t>(threads), n_chunks));
    }
}

TEST_CASE("for_each_chunk_balanced hands out every chunk once, on every thread count", "[parallel_ranges][threads]") {
  // Uneven work (the later chunks cost more), per-worker state, and counts with and without a
  // short last chunk: every index is visited exactly once, and each worker's own state stays its.
  for (const std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(1000), std::size_t(4096 * 5 + 17)}) {
    for (const int threads : {1, 2, 3, 8}) {
      std::vector<int> visits(n, 0);
      std::atomic<int> workers{0}, bad_chunks{0};  // (Catch's assertions are for the main thread)
      for_each_chunk_balanced(n, 64, threads, [&](auto&& next) {
        ++workers;
        std::vector<std::size_t> mine;  // per-worker state, as the callers' marks
        for (std::size_t begin = 0, end = 0; next(begin, end);) {
          if (!(begin < end && end <= n && end - begin <= 64 && begin % 64 == 0)) ++bad_chunks;
          for (std::size_t i = begin; i < end; ++i) {
            volatile double x = 0.0;
            for (std::size_t k = 0; k < i / 64; ++k) x = x + 1.0;
            mine.push_back(i);
          }
        }
        for (const std::size_t i : mine) ++visits[i];  // distinct indices per worker: no race
      });
      CAPTURE(n, threads);
      CHECK(bad_chunks.load() == 0);
      CHECK(std::count(visits.begin(), visits.end(), 1) == static_cast<long>(n));
      CHECK(workers.load() >= 1);
      CHECK(workers.load() <= std::max(1, threads));
    }
  }
}
