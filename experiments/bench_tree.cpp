// bench_tree: how fast the linear tree refines and balances, and how much memory a leaf costs.
//
// The workload is the paper's: a control parameter (a target level) that asks for level k on a
// boundary and nothing elsewhere, here a circle (2D) or a sphere (3D) of radius 0.35 in the unit
// cube. check_and_subdivide_quadrant then refines a band around the boundary to level k, and the
// 2:1 balance grades the tree away from it. Raising k from small to large walks the leaf count
// from about 10^4 to 10^7 in both dimensions.
//
// Usage: bench_tree [max_leaves]   (default 1.2e7; the largest run stops below it)
// Output: a table on stdout and results/bench_tree.csv.

#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "core/orthtree.hpp"

using namespace febemesh;

namespace {

/// Wall-clock and CPU time of one step. The CPU time is what "one core" means on a shared
/// machine: when other processes compete for the cores the wall clock stretches, CPU time not.
struct Stopwatch {
  std::chrono::steady_clock::time_point wall0 = std::chrono::steady_clock::now();
  double cpu0 = cpu_now();
  static double cpu_now() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  }
  double wall() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(); }
  double cpu() const { return cpu_now() - cpu0; }
};

/// The control parameter: level k in every box the sphere of radius r around the centre
/// crosses, 0 elsewhere (the paper's control points sit on the boundary).
template <int Dim> ControlFn<Dim> sphere_control(double r, int k) {
  return [r, k](const Box<Dim>& b) {
    double near2 = 0.0, far2 = 0.0;
    for (int d = 0; d < Dim; ++d) {
      const double lo = b.lo[d] - 0.5, hi = b.hi[d] - 0.5;
      const double n = lo > 0.0 ? lo : (hi < 0.0 ? -hi : 0.0);
      const double f = std::max(std::abs(lo), std::abs(hi));
      near2 += n * n;
      far2 += f * f;
    }
    return near2 <= r * r && far2 >= r * r ? double(k) : 0.0;
  };
}

/// Resident set size now (VmRSS) or its high-water mark (VmHWM), in bytes.
double status_bytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == field + ":") {
      double kb = 0;
      status >> kb;
      return kb * 1024.0;
    }
    std::getline(status, key);
  }
  return 0.0;
}

/// An order-sensitive checksum of the leaves, to compare runs without keeping two trees.
template <int Dim> std::uint64_t checksum(const Orthtree<Dim>& t) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const auto& c : t.leaves()) h = (h ^ (morton_key(c) * 64 + c.level)) * 1099511628211ULL;
  return h;
}

/// One size, run in a forked child so that the peak RSS belongs to this run alone. Writes one
/// CSV line and returns the number of balanced leaves through the exit pipe.
template <int Dim> void run(int k, const std::string& csv_path, int pipe_fd) {
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto control = sphere_control<Dim>(0.35, k);
  const double base = status_bytes("VmRSS");
  RefineOptions opt;

  // The same refinement on two threads first: identical leaves, checked by checksum below.
  opt.n_threads = 2;
  Stopwatch watch;
  std::uint64_t parallel_sum = 0;
  {
    const Orthtree<Dim> t2 = subdivide_by_control<Dim>(unit, control, opt);
    parallel_sum = checksum(t2);
  }
  const double refine2_s = watch.wall();

  // Refinement on one core; its memory peak is what a refinement costs (output vector growth).
  opt.n_threads = 1;
  watch = Stopwatch();
  const Orthtree<Dim> tree = subdivide_by_control<Dim>(unit, control, opt);
  const double refine_s = watch.wall(), refine_cpu = watch.cpu();
  const double refine_peak = status_bytes("VmHWM") - base;
  if (checksum(tree) != parallel_sum) {
    std::cerr << "parallel refinement differs from serial\n";
    std::exit(1);
  }

  // 2:1 balance across facets (the paper's rule), one core.
  watch = Stopwatch();
  const Orthtree<Dim> balanced = balance_2to1(tree, BalanceKind::Face);
  const double balance_s = watch.wall(), balance_cpu = watch.cpu();
  const double total_peak = status_bytes("VmHWM") - base;
  if (!is_complete(balanced) || !is_balanced(balanced)) {
    std::cerr << "balance produced an invalid tree\n";
    std::exit(1);
  }

  const double n = double(tree.n_leaves()), nb = double(balanced.n_leaves());
  std::printf("%dD k=%2d %9zu leaves | refine %5.1f M/s cpu (%5.1f wall), 2 threads %5.1f M/s wall, "
              "%5.1f B/leaf peak | balance -> %9zu leaves %5.1f M/s cpu (%5.1f wall), %5.1f B/leaf peak\n",
              Dim, k, tree.n_leaves(), 1e-6 * n / refine_cpu, 1e-6 * n / refine_s, 1e-6 * n / refine2_s,
              refine_peak / n, balanced.n_leaves(), 1e-6 * nb / balance_cpu, 1e-6 * nb / balance_s,
              total_peak / nb);
  std::fflush(stdout);
  std::ofstream csv(csv_path, std::ios::app);
  csv << Dim << ',' << k << ',' << tree.n_leaves() << ',' << refine_s << ',' << refine_cpu << ',' << refine2_s
      << ',' << refine_peak << ',' << balanced.n_leaves() << ',' << balance_s << ',' << balance_cpu << ','
      << total_peak << '\n';
  const std::uint64_t count = balanced.n_leaves();
  if (write(pipe_fd, &count, sizeof count) != ssize_t(sizeof count)) std::exit(1);
}

/// Runs one size in a child process; returns its balanced leaf count.
template <int Dim> std::size_t run_isolated(int k, const std::string& csv_path) {
  int fds[2];
  if (pipe(fds) != 0) return 0;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    run<Dim>(k, csv_path, fds[1]);
    std::_Exit(0);
  }
  close(fds[1]);
  std::uint64_t count = 0;
  if (read(fds[0], &count, sizeof count) != ssize_t(sizeof count)) count = 0;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::cerr << "run " << Dim << "D k=" << k << " failed\n";
    std::exit(1);
  }
  return std::size_t(count);
}

}  // namespace

int main(int argc, char** argv) {
  const double max_leaves = argc > 1 ? std::atof(argv[1]) : 1.2e7;
  std::filesystem::create_directories("results");
  const std::string csv = "results/bench_tree.csv";
  std::ofstream(csv) << "dim,level,leaves,refine_s,refine_cpu_s,refine_2threads_s,refine_peak_rss_bytes,"
                        "balanced_leaves,balance_s,balance_cpu_s,total_peak_rss_bytes\n";

  std::printf("stored bytes per leaf: sizeof(Cell<2>) = %zu, sizeof(Cell<3>) = %zu\n", sizeof(Cell<2>),
              sizeof(Cell<3>));
  std::printf("peak = VmHWM growth of a child process running only this size: refinement alone,\n"
              "then input tree + balanced tree + the balance's work arrays. Rates are leaves per\n"
              "second of CPU time (one core) and of wall-clock time (stretched when the machine is busy).\n\n");
  std::fflush(stdout);

  // A band around a curve holds about c 2^k leaves in 2D and c 4^k in 3D: each step of k
  // doubles (2D) or quadruples (3D) the work. Stop before the next step would pass max_leaves.
  for (int k = 8; 2.2 * double(run_isolated<2>(k, csv)) < max_leaves; ++k) {
  }
  std::printf("\n");
  std::fflush(stdout);
  for (int k = 5; 4.4 * double(run_isolated<3>(k, csv)) < max_leaves; ++k) {
  }
  std::printf("\nwrote %s\n", csv.c_str());
  return 0;
}
