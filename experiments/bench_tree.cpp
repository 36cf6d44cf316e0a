// bench_tree: how fast the linear tree refines and balances, and how much memory a leaf costs.
//
// The workload is the paper's: a control parameter (a target level) that asks for level k on a
// boundary and nothing elsewhere, here a circle (2D) or a sphere (3D) of radius 0.35 in the unit
// cube. check_and_subdivide_quadrant then refines a band around the boundary to level k, and the
// 2:1 balance grades the tree away from it. Raising k from small to large walks the leaf count
// from about 10^4 to 10^7 in both dimensions.
//
// Usage: bench_tree [max_leaves] [repetitions] [dim]   (defaults 1.2e7, 3, both; the largest run
// stops below max_leaves; times are the best of the repetitions)
// Output: a table on stdout and results/bench_tree.csv.
//
// The two-thread speedups (columns x) mean something only when both cores are free: the last
// column is the 1-minute load average, and a run beside other processes (load >= 1) shows their
// share of the cores, not the code's scaling.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/orthtree.hpp"
#include "core/process_stats.hpp"

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

/// The 1-minute load average: with 2 cores, a load above ~1 before a run means another process
/// competed for the second core, and the 2-thread columns then understate the speedup.
double load_average() {
  double load = -1.0;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = -1.0;
    std::fclose(f);
  }
  return load;
}

/// What two threads can gain on this machine right now: the speedup of a loop with no memory
/// traffic and no sharing, split over two threads (best of 3 each). On two free cores it is ~2;
/// beside other processes it drops to what they leave, and the tree's x columns cannot exceed it.
double control_speedup() {
  const auto spin = [](std::uint64_t n, std::uint64_t* out) {
    std::uint64_t x = 88172645463325252ULL;
    for (std::uint64_t i = 0; i < n; ++i) x ^= (x << 13) ^ (x >> 7) ^ (x << 17) ^ i;
    *out = x;
  };
  constexpr std::uint64_t n = 200000000;
  std::uint64_t sink[2] = {0, 0};
  double t1 = 1e300, t2 = 1e300;
  for (int r = 0; r < 3; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    spin(n, &sink[0]);
    t1 = std::min(t1, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    t0 = std::chrono::steady_clock::now();
    std::thread other(spin, n / 2, &sink[1]);
    spin(n / 2, &sink[0]);
    other.join();
    t2 = std::min(t2, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  if (sink[0] == 42 && sink[1] == 42) std::printf(" ");  // keep the loops
  return t1 / t2;
}

/// Memory cost of one operation: the growth of the peak resident set while it runs, from the
/// resident set just before it (the peak is reset first). Free heap memory is returned to the
/// system first, or the operation could reuse pages that are already counted in the base.
class PeakDelta {
 public:
  PeakDelta() {
    malloc_trim(0);
    if (!reset_peak_memory()) std::cerr << "cannot reset the peak resident set; B/leaf is an upper bound\n";
    base_ = double(current_memory_bytes());
  }
  double bytes() const { return double(peak_memory_bytes()) - base_; }

 private:
  double base_ = 0.0;
};

/// An order-sensitive checksum of the leaves, to compare runs without keeping two trees.
template <int Dim> std::uint64_t checksum(const Orthtree<Dim>& t) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const auto& c : t.leaves()) h = (h ^ (morton_key(c) * 64 + c.level)) * 1099511628211ULL;
  return h;
}

/// Best (minimum) wall and CPU time of a few repetitions: other engineers' builds share the two
/// cores, and a repetition that was not interrupted is the closest to the machine's real speed.
struct Best {
  double wall = 1e300, cpu = 1e300;
  void add(const Stopwatch& w) {
    wall = std::min(wall, w.wall());
    cpu = std::min(cpu, w.cpu());
  }
};

/// One size, run in a forked child so that the memory figures belong to this run alone. Prints
/// one table row, writes one CSV line and returns the number of balanced leaves through the pipe.
template <int Dim> void run(int k, int reps, const std::string& csv_path, int pipe_fd) {
  const Box<Dim> unit{Point<Dim>::Zero(), Point<Dim>::Ones()};
  const auto control = sphere_control<Dim>(0.35, k);
  RefineOptions opt1, opt2;
  opt2.n_threads = 2;

  // Serial refinement; the last repetition also gives its memory peak (the earlier ones have
  // paged in the code, which is not the refinement's memory).
  Best refine1, refine2, balance1, balance2;
  double refine_peak = 0.0;
  std::uint64_t serial_sum = 0;
  for (int r = 0; r < reps; ++r) {
    const PeakDelta mem;
    const Stopwatch watch;
    const Orthtree<Dim> t = subdivide_by_control<Dim>(unit, control, opt1);
    refine1.add(watch);
    if (r == reps - 1) refine_peak = mem.bytes();
    serial_sum = checksum(t);
  }
  // The same refinement on two threads: identical leaves (same checksum), and how much faster.
  for (int r = 0; r < reps; ++r) {
    const Stopwatch watch;
    const Orthtree<Dim> t = subdivide_by_control<Dim>(unit, control, opt2);
    refine2.add(watch);
    if (checksum(t) != serial_sum) {
      std::cerr << "parallel refinement differs from serial\n";
      std::exit(1);
    }
  }

  const Orthtree<Dim> tree = subdivide_by_control<Dim>(unit, control, opt1);
  // 2:1 balance across facets (the paper's rule), one core. The input tree is resident before
  // the balance starts, so the peak growth is the output plus the balance's work arrays.
  double balance_peak = 0.0;
  std::size_t n_balanced = 0;
  double container = 0.0;
  for (int r = 0; r < reps; ++r) {
    const PeakDelta mem;
    const Stopwatch watch;
    const Orthtree<Dim> balanced = balance_2to1(tree, BalanceKind::Face);
    balance1.add(watch);
    if (r == reps - 1) {
      balance_peak = mem.bytes();
      n_balanced = balanced.n_leaves();
      container = double(balanced.leaves().capacity() * sizeof(Cell<Dim>)) / double(n_balanced);
      if (!is_complete(balanced) || !is_balanced(balanced)) {
        std::cerr << "balance produced an invalid tree\n";
        std::exit(1);
      }
    }
  }

  // The same balance on two threads: identical leaves, and how much faster.
  BalanceOptions bopt2;
  bopt2.n_threads = 2;
  const std::uint64_t balanced_sum = checksum(balance_2to1(tree, BalanceKind::Face));
  for (int r = 0; r < reps; ++r) {
    const Stopwatch watch;
    const Orthtree<Dim> balanced = balance_2to1(tree, BalanceKind::Face, bopt2);
    balance2.add(watch);
    if (checksum(balanced) != balanced_sum) {
      std::cerr << "parallel balance differs from serial\n";
      std::exit(1);
    }
  }

  const double n = double(tree.n_leaves()), nb = double(n_balanced);
  std::printf("%dD %3d %10zu %7.1f %7.1f %7.1f %6.2f %7.1f | %10zu %7.1f %7.1f %7.1f %6.2f %7.1f %7.1f | %5.2f\n",
              Dim, k, tree.n_leaves(), 1e-6 * n / refine1.cpu, 1e-6 * n / refine1.wall, 1e-6 * n / refine2.wall,
              refine1.wall / refine2.wall, refine_peak / n, n_balanced, 1e-6 * nb / balance1.cpu,
              1e-6 * nb / balance1.wall, 1e-6 * nb / balance2.wall, balance1.wall / balance2.wall,
              balance_peak / nb, container, load_average());
  std::fflush(stdout);
  std::ofstream csv(csv_path, std::ios::app);
  csv << Dim << ',' << k << ',' << tree.n_leaves() << ',' << refine1.wall << ',' << refine1.cpu << ','
      << refine2.wall << ',' << refine_peak << ',' << n_balanced << ',' << balance1.wall << ',' << balance1.cpu
      << ',' << balance2.wall << ',' << balance_peak << ',' << container * nb << ',' << load_average() << '\n';
  const std::uint64_t count = n_balanced;
  if (write(pipe_fd, &count, sizeof count) != ssize_t(sizeof count)) std::exit(1);
}

/// Runs one size in a child process; returns its balanced leaf count.
template <int Dim> std::size_t run_isolated(int k, int reps, const std::string& csv_path) {
  int fds[2];
  if (pipe(fds) != 0) return 0;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    run<Dim>(k, reps, csv_path, fds[1]);
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
  const int reps = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  std::filesystem::create_directories("results");
  const std::string csv = "results/bench_tree.csv";
  std::ofstream(csv) << "dim,level,leaves,refine_s,refine_cpu_s,refine_2threads_s,refine_peak_bytes,"
                        "balanced_leaves,balance_s,balance_cpu_s,balance_2threads_s,balance_peak_bytes,balanced_container_bytes,"
                        "load_1min\n";

  std::printf("stored bytes per leaf: sizeof(Cell<2>) = %zu, sizeof(Cell<3>) = %zu\n", sizeof(Cell<2>),
              sizeof(Cell<3>));
  std::printf("rates: leaves per second, best of %d runs, of CPU time and of wall-clock time (one thread);\n"
              "2thr: wall-clock rate on two threads (same checksum as serial), x = speedup over one thread.\n"
              "load: 1-minute load average after the size (other processes; speedups need it near 0).\n"
              "B/leaf: growth of the peak resident set during the operation over the leaves it made\n"
              "(balance: the input tree is resident before and not counted); cont: the balanced tree's\n"
              "own vector (capacity x sizeof) per leaf.\n\n",
              reps);
  std::printf("control: a compute-only loop runs %.2fx faster on two threads than on one right now\n"
              "(the ceiling for the x columns; ~2 on two free cores)\n\n",
              control_speedup());
  std::printf("   k     leaves  refine    wall    2thr      x  B/leaf |   balanced balance    wall    2thr      x  B/leaf    cont |  load\n");
  std::fflush(stdout);

  // A band around a curve holds about c 2^k leaves in 2D and c 4^k in 3D: each step of k
  // doubles (2D) or quadruples (3D) the work. Stop before the next step would pass max_leaves.
  const int only_dim = argc > 3 ? std::atoi(argv[3]) : 0;
  if (only_dim != 3) {
    for (int k = 8; 2.2 * double(run_isolated<2>(k, reps, csv)) < max_leaves; ++k) {
    }
  }
  if (only_dim != 2) {
    for (int k = 5; 4.4 * double(run_isolated<3>(k, reps, csv)) < max_leaves; ++k) {
    }
  }
  std::printf("\ncontrol at the end: %.2fx\nwrote %s\n", control_speedup(), csv.c_str());
  return 0;
}
