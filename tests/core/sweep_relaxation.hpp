#pragma once
// A test workload for Gauss-Seidel sweeps (core/ordered_sweep.hpp, core/partitioned_sweep.hpp):
// a nonlinear relaxation whose result depends on the visiting order, with the skip flags the
// mesh sweeps use.

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/ordered_sweep.hpp"  // mark()

namespace febemesh::test {

/// x[v] moves towards a function of its neighbours' mean unless it was settled, and a move
/// marks its neighbours unsettled (like the smoothing's skip flags). adj[v]: v's neighbours.
struct Relaxation {
  const std::vector<std::vector<std::int32_t>>& adj;
  std::vector<double> x;
  std::vector<std::uint8_t> settled;
  explicit Relaxation(const std::vector<std::vector<std::int32_t>>& a) : adj(a), x(a.size()), settled(a.size(), 0) {
    for (std::size_t v = 0; v < a.size(); ++v) x[v] = std::cos(static_cast<double>(v));
  }
  void visit(std::int32_t v) {
    const auto& nb = adj[static_cast<std::size_t>(v)];
    if (settled[static_cast<std::size_t>(v)] || nb.empty()) return;
    double mean = 0.0;
    for (const std::int32_t u : nb) mean += x[static_cast<std::size_t>(u)];
    mean /= static_cast<double>(nb.size());
    const double target = std::sin(3.0 * mean) + 0.5 * x[static_cast<std::size_t>(v)];
    if (std::abs(target - x[static_cast<std::size_t>(v)]) < 0.05) {
      settled[static_cast<std::size_t>(v)] = 1;
      return;
    }
    x[static_cast<std::size_t>(v)] = target;
    for (const std::int32_t u : nb) mark(settled[static_cast<std::size_t>(u)], 0);
  }
};

}  // namespace febemesh::test
