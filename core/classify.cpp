// IN / OUT / PARTIAL of every leaf (paper, "Find interior quadrants"). Each leaf's answer depends
// only on its own box, so threads take contiguous ranges and write disjoint slots: the result is
// the same for any thread count.

#include <algorithm>
#include <exception>
#include <thread>

#include "core/orthtree.hpp"

namespace febemesh {

template <int Dim>
std::vector<Side> classify(const Orthtree<Dim>& t, const Boundary<Dim>& b, int n_threads) {
  std::vector<Side> sides(t.n_leaves(), Side::Partial);
  const auto run = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) sides[i] = b.classify(geometry(t, t.leaf(i)));
  };
  const std::size_t n = t.n_leaves();
  const std::size_t n_workers = std::size_t(std::clamp(n_threads, 1, 256));
  if (n_workers == 1 || n < 2 * n_workers) {
    run(0, n);
    return sides;
  }
  std::vector<std::exception_ptr> errors(n_workers);
  std::vector<std::thread> threads;
  for (std::size_t w = 1; w < n_workers; ++w) {
    threads.emplace_back([&, w] {
      try {
        run(n * w / n_workers, n * (w + 1) / n_workers);
      } catch (...) {
        errors[w] = std::current_exception();
      }
    });
  }
  try {
    run(0, n / n_workers);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& th : threads) th.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return sides;
}

template std::vector<Side> classify<2>(const Orthtree<2>&, const Boundary<2>&, int);
template std::vector<Side> classify<3>(const Orthtree<3>&, const Boundary<3>&, int);

}  // namespace febemesh
