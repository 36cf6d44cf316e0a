// Benchmark: how fast does the 3D boundary answer the octree pipeline's questions?
//
// For each surface we read and validate it (closedness, manifoldness, self-intersections,
// orientation), build the AABB tree and the features, then time, on one core, the queries the
// pipeline asks millions of times: the closest point (projection of cell corners), the inside
// test, the local minima of the distance, segment crossing and box classification. Query
// points are uniform in the root box from a fixed seed, so every run asks the same questions.
// A second set of points lies within 2% of the diagonal of the surface, where the pipeline
// actually projects. Results: printed, and written to results/bench_surface_queries.json.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dim3/surface_boundary.hpp"

using namespace febemesh;
using namespace febemesh::dim3;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::vector<P3> query_points(const Box<3>& box, int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::vector<P3> pts(n);
  for (P3& p : pts)
    for (int d = 0; d < 3; ++d) p[d] = box.lo[d] + box.extent()[d] * (gen() / 4294967296.0);
  return pts;
}

/// Points within 2% of the diagonal of the surface: where the pipeline projects cell corners.
std::vector<P3> near_points(const SurfaceBoundary& s, int n, unsigned seed) {
  std::mt19937 gen(seed);
  auto unit = [&] { return gen() / 4294967296.0; };
  const double reach = 0.02 * s.bounding_box().extent().norm();
  std::vector<P3> pts(n);
  for (P3& p : pts) {
    const Triangle& t = s.triangles()[gen() % s.triangles().size()];
    double u = unit(), v = unit();
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const P3 &a = s.vertices()[t[0]], &b = s.vertices()[t[1]], &c = s.vertices()[t[2]];
    p = a + u * (b - a) + v * (c - a) + reach * (2.0 * unit() - 1.0) * (b - a).cross(c - a).normalized();
  }
  return pts;
}

/// Runs `query` over every point and returns queries per second; `sink` keeps the work alive.
template <class F> double rate(const std::vector<P3>& pts, F&& query, double& sink) {
  const auto t0 = Clock::now();
  for (const P3& p : pts) sink += query(p);
  return pts.size() / seconds_since(t0);
}

}  // namespace

int main() {
  const std::string data = std::string(FEBEMESH_DATA_DIR) + "/3d/";
  nlohmann::json report = nlohmann::json::array();
  double sink = 0.0;
  std::printf("%-14s %7s %6s %6s %9s %9s | %12s %12s %12s %12s %12s %12s\n", "surface", "tris", "fedges",
              "corner", "load [s]", "tree [ms]", "closest/s", "inside/s", "minima3/s", "segment/s",
              "classify/s", "level/s");
  for (const char* name : {"fandisk.off", "elephant.off", "anchor.off", "sphere966.off"}) {
    // 1. Read, validate and orient; build the tree and the features.
    auto t0 = Clock::now();
    const SurfaceBoundary s = SurfaceBoundary::from_file(data + name);
    const double load = seconds_since(t0);
    t0 = Clock::now();
    const AabbTree tree(s.vertices(), s.triangles());
    const double tree_ms = 1e3 * seconds_since(t0);

    // 2. Queries in the root box, where the pipeline's cell corners live.
    const Box<3> root = s.root_box();
    const std::vector<P3> pts = query_points(root, 200000, 12345u);
    const std::vector<P3> few(pts.begin(), pts.begin() + 20000);
    const std::vector<P3> near = near_points(s, 200000, 777u);
    const double closest_near = rate(near, [&](const P3& p) { return s.closest_point(p).distance; }, sink);
    const double minima_near = rate(near, [&](const P3& p) { return double(s.closest_points(p, 3).size()); }, sink);
    const double closest = rate(pts, [&](const P3& p) { return s.closest_point(p).distance; }, sink);
    const double inside = rate(pts, [&](const P3& p) { return s.is_inside(p) ? 1.0 : 0.0; }, sink);
    const double minima = rate(few, [&](const P3& p) { return double(s.closest_points(p, 3).size()); }, sink);
    const double diag = root.extent().norm();
    const double segment = rate(pts, [&](const P3& p) {
      return s.segment_crosses(p, p + 0.05 * diag * P3(0.48, -0.6, 0.64)) ? 1.0 : 0.0;
    }, sink);
    auto cell = [&](const P3& p) {
      Box<3> b;
      b.lo = p;
      b.hi = p + P3::Constant(root.extent()[0] / 64.0);  // a level-6 cell
      return b;
    };
    const double classify = rate(pts, [&](const P3& p) { return double(s.classify(cell(p))); }, sink);
    const double level = rate(pts, [&](const P3& p) { return s.control_level(cell(p)); }, sink);

    std::printf("%-14s %7d %6d %6d %9.3f %9.2f | %12.0f %12.0f %12.0f %12.0f %12.0f %12.0f\n", name,
                s.surface().n_triangles(), s.features().n_feature_edges(), s.features().n_corners(), load,
                tree_ms, closest, inside, minima, segment, classify, level);
    std::printf("%-14s %43s | %12.0f %12s %12.0f   (points within 2%% of the diagonal of the surface)\n", "",
                "near the surface:", closest_near, "", minima_near);
    report.push_back({{"surface", name},
                      {"triangles", s.surface().n_triangles()},
                      {"feature_edges", s.features().n_feature_edges()},
                      {"corners", s.features().n_corners()},
                      {"euler_characteristic", s.euler_characteristic()},
                      {"load_seconds", load},
                      {"tree_ms", tree_ms},
                      {"closest_per_s", closest},
                      {"closest_near_per_s", closest_near},
                      {"minima3_near_per_s", minima_near},
                      {"inside_per_s", inside},
                      {"minima3_per_s", minima},
                      {"segment_per_s", segment},
                      {"classify_level6_per_s", classify},
                      {"control_level_per_s", level}});
  }
  std::filesystem::create_directories("results");
  std::ofstream("results/bench_surface_queries.json") << report.dump(2) << "\n";
  std::printf("(checksum %.6g) written results/bench_surface_queries.json\n", sink);
  return 0;
}
