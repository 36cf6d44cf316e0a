#pragma once
// How fast each CPU reads memory, for the benchmarks (issue 8). On this VM (2 vCPUs) random
// reads from a 64 MiB array took up to 1.43x as long on one vCPU as on the other, and which one
// is slow changes over minutes (session 45: cpu1 0.30 s against cpu0 0.22 s, later cpu0 0.30 s
// against cpu1 0.21 s, later still 1.02-1.22x apart), while arithmetic runs at the same speed on
// both. A one-thread run was then up to 1.3-1.5x slower on the slow vCPU (bench_mesh3d
// sphere966 at 10^6 tets pinned: 2.89 s against 3.76-4.02 s; bench_mesh2d flange 0.54 against
// 0.83 s), and a two-thread run whose work is split in equal halves waits for the slow one. So every bench prints this probe beside its times, and --pin-one-thread runs the
// one-thread timings on the vCPU that is fast at that moment (the baseline of a speedup then
// being the better one-thread time).

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace febemesh::bench {

struct CpuMemoryProbe {
  int cpu = 0;
  double ns_per_read = 0.0;  ///< random 8-byte reads from a 64 MiB array, one at a time in flight
};

/// The CPUs this process may run on.
inline std::vector<int> allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> out;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return out;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) out.push_back(c);
  return out;
}

/// Pins the calling thread to `cpu` (cpu >= 0) for its lifetime and restores its mask after;
/// threads it starts meanwhile inherit the pin. cpu < 0: nothing.
class PinnedTo {
 public:
  explicit PinnedTo(int cpu) {
    if (cpu < 0 || pthread_getaffinity_np(pthread_self(), sizeof saved_, &saved_) != 0) return;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    pinned_ = pthread_setaffinity_np(pthread_self(), sizeof one, &one) == 0;
  }
  ~PinnedTo() {
    if (pinned_) pthread_setaffinity_np(pthread_self(), sizeof saved_, &saved_);
  }
  PinnedTo(const PinnedTo&) = delete;
  PinnedTo& operator=(const PinnedTo&) = delete;

 private:
  cpu_set_t saved_{};
  bool pinned_ = false;
};

/// Each allowed CPU's time for `reads` dependent random reads from a 64 MiB array (about 0.1 s a
/// CPU here), one CPU after the other on a thread pinned to it.
inline std::vector<CpuMemoryProbe> probe_cpu_memory(std::size_t reads = 10'000'000) {
  constexpr std::size_t n = (std::size_t(64) << 20) / sizeof(std::uint64_t);  // a power of two
  std::vector<std::uint64_t> a(n);
  for (std::size_t i = 0; i < n; ++i) a[i] = i * 0x9E3779B97F4A7C15ull;
  std::vector<CpuMemoryProbe> out;
  for (const int cpu : allowed_cpus()) {
    double seconds = 0.0;
    std::thread t([&] {
      const PinnedTo pin(cpu);
      const auto t0 = std::chrono::steady_clock::now();
      std::uint64_t x = 88172645463325252ull, s = 0;
      for (std::size_t r = 0; r < reads; ++r) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        s += a[(x ^ s) & (n - 1)];  // the next index depends on the read: one read in flight
      }
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      [[maybe_unused]] volatile std::uint64_t sink = s;  // the reads are not optimised away
    });
    t.join();
    out.push_back({cpu, 1e9 * seconds / static_cast<double>(std::max<std::size_t>(reads, 1))});
  }
  return out;
}

/// The CPU with the fastest reads (-1 without a probe).
inline int fastest_cpu(const std::vector<CpuMemoryProbe>& p) {
  const auto it = std::min_element(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.ns_per_read < b.ns_per_read; });
  return it == p.end() ? -1 : it->cpu;
}

/// The probe for a bench's .json: [{"cpu": 0, "ns_per_read": 92.1}, ...].
inline nlohmann::json probe_json(const std::vector<CpuMemoryProbe>& p) {
  nlohmann::json j = nlohmann::json::array();
  for (const CpuMemoryProbe& c : p) j.push_back({{"cpu", c.cpu}, {"ns_per_read", c.ns_per_read}});
  return j;
}

/// "cpu0 92.1 ns, cpu1 128.3 ns a random read from 64 MiB (slowest / fastest 1.39x)".
inline std::string describe(const std::vector<CpuMemoryProbe>& p) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(1);
  double lo = 0.0, hi = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    os << (i ? ", " : "") << "cpu" << p[i].cpu << " " << p[i].ns_per_read << " ns";
    lo = i == 0 ? p[i].ns_per_read : std::min(lo, p[i].ns_per_read);
    hi = std::max(hi, p[i].ns_per_read);
  }
  os << " a random read from 64 MiB";
  if (p.size() > 1 && lo > 0) {
    os.precision(2);
    os << " (slowest / fastest " << hi / lo << "x)";
  }
  return os.str();
}

}  // namespace febemesh::bench
