#pragma once
// The cell size (the CLI's --size) whose mesh has a given element count, for the benchmarks
// (bench_mesh2d --sizes, bench_mesh3d --tets): untimed runs along a line in log(count) against
// log(size). The counts of levels alone step 4x (2D) to 8x (3D) a level.

#include <algorithm>
#include <cmath>
#include <vector>

namespace febemesh::bench {

struct SizeAim {
  double size = 0.0;
  double count = 0.0;  ///< at `size`, from the search's own run
  int runs = 0;        ///< untimed runs made
};

/// At most 8 runs of count_at(size) (<= 0: refused, e.g. past the tree's limit): the first at
/// `first`, then along the line through the two runs nearest `target` (its slope d log(count) /
/// d log(size) clamped to [slope_lo, slope_hi]; `slope` until there are two), until a count is
/// within `tolerance` of the target; a refused run doubles the size. The nearest run's size.
template <class CountAt>
SizeAim aim_size(double first, double target, double tolerance, double slope, double slope_lo, double slope_hi,
                 CountAt&& count_at) {
  struct Point {
    double size, count;
  };
  std::vector<Point> runs;
  const auto miss = [&](const Point& p) { return p.count > 0 ? std::abs(std::log(p.count / target)) : 1e300; };
  double size = first;
  for (int k = 0; k < 8; ++k) {
    const double n = count_at(size);
    runs.push_back({size, n});
    if (n > 0 && std::abs(n / target - 1.0) <= tolerance) break;
    std::vector<Point> ok;
    for (const Point& p : runs)
      if (p.count > 0) ok.push_back(p);
    if (ok.empty()) {
      size *= 2.0;  // refused: coarser
      continue;
    }
    std::sort(ok.begin(), ok.end(), [&](const Point& a, const Point& b) { return miss(a) < miss(b); });
    double s = slope;
    if (ok.size() >= 2 && ok[0].size != ok[1].size && ok[0].count != ok[1].count)
      s = std::clamp(std::log(ok[0].count / ok[1].count) / std::log(ok[0].size / ok[1].size), slope_lo, slope_hi);
    const double next = ok[0].size * std::pow(target / ok[0].count, 1.0 / s);
    if (std::any_of(runs.begin(), runs.end(), [&](const Point& p) { return std::abs(p.size / next - 1.0) < 1e-6; })) break;
    size = next;
  }
  const auto best = std::min_element(runs.begin(), runs.end(), [&](const Point& a, const Point& b) { return miss(a) < miss(b); });
  return {best->size, best->count, static_cast<int>(runs.size())};
}

}  // namespace febemesh::bench
