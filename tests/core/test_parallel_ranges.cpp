#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
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
