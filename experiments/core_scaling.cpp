// core_scaling: does this machine run two threads twice as fast as one? (issue 8)
//
// The 2-thread runs of the 3D pipeline gave about 1.0x (docs/measurements.md). Before blaming
// the scheduler, measure what the cores themselves give: the same work on 1 and on 2 threads,
// each thread with its own data, no sharing, no locks. Three kinds of work:
//   compute - a dependent floating-point chain in registers (what SMT siblings share);
//   cache   - reads and writes within 256 KB a thread (L2);
//   memory  - one 8-byte read and write every 64 bytes over 64 MB a thread (DRAM bandwidth).
// Throughput x2.00 means two independent cores; about x1.0-1.3 for compute means the two
// virtual CPUs share one physical core (SMT) or the machine is busy; run it on a quiet machine
// (check `uptime` and `top` first) and repeat.
//
// Usage: core_scaling [--repeat N]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace {

volatile double sink;

void compute(long n) {
  double x = 1.0;
  for (long i = 0; i < n; ++i) x = x * 1.0000001 + std::sqrt(x) * 1e-9;
  sink = x;
}

void strided(std::vector<double>& a, int reps) {
  double s = 0;
  for (int r = 0; r < reps; ++r)
    for (std::size_t i = 0; i < a.size(); i += 8) s += a[i], a[i] = s * 1e-9;
  sink = s;
}

/// Wall seconds for f(t) on `threads` threads at once.
template <class F> double timed(int threads, const F& f) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> th;
  for (int t = 0; t < threads; ++t) th.emplace_back([&, t] { f(t); });
  for (auto& x : th) x.join();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void row(const char* name, double one, double two) {
  std::printf("%-8s 1 thread %.3f s, 2 threads (the same work each) %.3f s: throughput x%.2f\n", name, one, two,
              2.0 * one / two);
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 1;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--repeat") repeat = std::stoi(argv[i + 1]);
  std::vector<std::vector<double>> big(2, std::vector<double>((64u << 20) / sizeof(double)));
  std::vector<std::vector<double>> small(2, std::vector<double>((256u << 10) / sizeof(double)));
  for (int r = 0; r < repeat; ++r) {
    const long n = 200000000;
    row("compute", timed(1, [&](int) { compute(n); }), timed(2, [&](int) { compute(n); }));
    row("cache", timed(1, [&](int t) { strided(small[t], 20000); }), timed(2, [&](int t) { strided(small[t], 20000); }));
    row("memory", timed(1, [&](int t) { strided(big[t], 20); }), timed(2, [&](int t) { strided(big[t], 20); }));
  }
}
