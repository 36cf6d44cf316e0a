// sweep_profile: how much parallelism the in-order sweeps of the 3D smoothing stage have, and
// where the second thread's time goes (issue 8).
//
// The guarded smoothing (core/smooth.cpp) and the tet optimiser (dim3/tet_optimize.cpp) visit
// their nodes as the DAG of an in-order Gauss-Seidel sweep allows (core/ordered_sweep.hpp). With
// sweep_probe set, every run of such a sweep records its size, the DAG's longest path (by node
// count: the depth; and weighted by the visits' measured times: the critical time), the time to
// build the DAG, the visits' own summed time, and on several threads the time the threads spent
// asleep or waiting for the scheduler's lock. total visit time / critical time bounds the
// speedup any scheduler can get from that DAG.
//
// Usage: sweep_profile [SURFACE] [--level L] [--threads 1,2] [--all]
// Prints one line per thread count with the sums over all sweeps (and with --all one line per
// sweep). Timing every visit adds ~40 ns a visit; compare the columns, not the absolute stage
// times, with an uninstrumented run.

#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "core/ordered_sweep.hpp"
#include "dim3/pipeline3d.hpp"
#include "dim3/read_surface.hpp"
#include "dim3/surface_boundary.hpp"

using namespace febemesh;

int main(int argc, char** argv) {
  std::string path = std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off";
  int level = 5;
  std::vector<int> thread_counts{1, 2};
  bool all = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--level" && i + 1 < argc) {
      level = std::stoi(argv[++i]);
    } else if (a == "--threads" && i + 1 < argc) {
      thread_counts.clear();
      std::stringstream ss(argv[++i]);
      for (std::string item; std::getline(ss, item, ',');) thread_counts.push_back(std::stoi(item));
    } else if (a == "--shares" && i + 1 < argc) {
      shares_per_thread = static_cast<std::size_t>(std::stoi(argv[++i]));
    } else if (a == "--all") {
      all = true;
    } else {
      path = a;
    }
  }
  std::cout << path << " level " << level << "\n";
  for (const int threads : thread_counts) {
    // The pipeline as the CLI runs it, with every sweep recorded.
    SweepProbe probe;
    sweep_probe.store(&probe);
    dim3::SurfaceBoundary s = dim3::SurfaceBoundary::from_file(path);
    dim3::Options3d opt;
    opt.level = level;
    opt.n_threads = threads;
    const dim3::Result3d r = dim3::mesh3d(s, opt);
    sweep_probe.store(nullptr);
    double smoothing = 0.0;
    for (const StageTime& st : r.times)
      if (st.name == "smoothing") smoothing += st.seconds;

    SweepRecord sum;
    std::size_t max_depth = 0;
    for (const SweepRecord& x : probe.runs) {
      sum.nodes += x.nodes, sum.edges += x.edges, sum.depth += x.depth;
      sum.build_s += x.build_s, sum.run_s += x.run_s, sum.visit_s += x.visit_s, sum.critical_s += x.critical_s;
      sum.wait_s += x.wait_s, sum.batches += x.batches, sum.cpu_s += x.cpu_s, sum.foreign += x.foreign, sum.foreign_s += x.foreign_s;
      for (std::size_t k = 0; k < x.block_sizes.size(); ++k) sum.block_critical_s[k] += x.block_critical_s[k];
      max_depth = std::max(max_depth, x.depth);
      if (all)
        std::printf("  run: nodes %8zu edges %9zu depth %6zu build %.4f run %.4f visits %.4f critical %.5f "
                    "wait %.4f batches %zu\n",
                    x.nodes, x.edges, x.depth, x.build_s, x.run_s, x.visit_s, x.critical_s, x.wait_s, x.batches);
    }
    std::printf("threads %d: smoothing stage %.3f s; %zu sweep runs, %zu visits, %zu DAG edges; depth sum %zu "
                "(max %zu); DAG builds %.3f s; runs %.3f s wall; visits %.3f s; critical %.4f s "
                "(visits / critical %.0f); runs' CPU %.3f s; waiting %.3f s; %zu batches (%.1f visits each), %zu visits from another thread's share (%.3f s, %.2f us each; the rest %.2f us each)\n",
                threads, smoothing, probe.runs.size(), sum.nodes, sum.edges, sum.depth, max_depth, sum.build_s,
                sum.run_s, sum.visit_s, sum.critical_s, sum.critical_s > 0 ? sum.visit_s / sum.critical_s : 0.0,
                sum.cpu_s, sum.wait_s, sum.batches, sum.batches > 0 ? double(sum.nodes) / double(sum.batches) : 0.0, sum.foreign, sum.foreign_s,
                sum.foreign > 0 ? 1e6 * sum.foreign_s / double(sum.foreign) : 0.0,
                1e6 * (sum.visit_s - sum.foreign_s) / double(std::max<std::size_t>(1, sum.nodes - sum.foreign)));
    for (std::size_t k = 0; k < sum.block_sizes.size(); ++k)
      std::printf("  blocks of %zu positions: critical %.4f s (visits / critical %.1f)\n", sum.block_sizes[k],
                  sum.block_critical_s[k], sum.block_critical_s[k] > 0 ? sum.visit_s / sum.block_critical_s[k] : 0.0);
  }
}
