#pragma once
// In-order node sweeps on several threads with the serial result, bit for bit (issue 8).
//
// A Gauss-Seidel sweep (the guarded smoothing, the tet optimiser) visits the nodes of a graph
// in increasing order, and the visit of v reads v and its neighbours and writes v (and marks its
// neighbours, below). Such a sweep computes the same numbers when v is visited as soon as its
// neighbours u < v in the sweep are done, in whatever order and on whatever thread: every
// neighbour u < v is still visited before v and every u > v after it. The sweep is a DAG
// (edges from lower to higher neighbours) scheduled as it unfolds, as for sparse triangular
// solves (Anderson & Saad 1989, there by levels). No barriers: on a loaded machine a thread the
// kernel parks holds up only the nodes that wait for the one it holds, not a whole level.
// The order of the mesh's nodes, which the serial sweep keeps, is unchanged, so any thread count
// gives the serial mesh.
//
// A visit may write to a neighbour's flag only a value that every writer writes (a "moved" or
// "stale" mark), through mark(): two nodes visited at once may mark the same neighbour.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <ctime>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <queue>
#include <span>
#include <thread>
#include <utility>
#include <vector>

#include "core/parallel_ranges.hpp"
#include "core/worker_pool.hpp"

namespace febemesh {

/// Sets flag = value where other threads may set the same flag to the same value meanwhile.
inline void mark(std::uint8_t& flag, std::uint8_t value) {
  std::atomic_ref<std::uint8_t>(flag).store(value, std::memory_order_relaxed);
}

/// CPU time of the calling thread, seconds.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// One run of an OrderedSweep as measured when sweep_probe is set (experiments/sweep_profile).
struct SweepRecord {
  std::size_t nodes = 0, edges = 0;  ///< the sweep's nodes and DAG edges (0 on one thread)
  int threads = 1;
  std::size_t depth = 0;       ///< nodes on the DAG's longest path (critical path, unit costs)
  double build_s = 0.0;        ///< building the DAG (once per OrderedSweep, in its first run)
  double run_s = 0.0;          ///< the run, wall
  double visit_s = 0.0;        ///< sum of the visits' own times
  double critical_s = 0.0;     ///< the longest path weighted by those times
  /// The same for whole blocks of block_sizes[k] consecutive positions (a block after every
  /// block holding an earlier neighbour of one of its nodes; one thread per block).
  static constexpr std::array<std::size_t, 4> block_sizes{64, 256, 1024, 4096};
  std::array<double, 4> block_critical_s{};
  double wait_s = 0.0;         ///< threads asleep or waiting for the lock, summed
  double cpu_s = 0.0;          ///< the threads' CPU time in the run, summed
  std::size_t batches = 0;     ///< lock acquisitions that took nodes
  std::size_t foreign = 0;     ///< visits a thread took from another thread's share
  double foreign_s = 0.0;      ///< their summed visit times
};
/// When set, every OrderedSweep appends one record per run (for measurements only: the DAG
/// is then built on one thread too, and every visit is timed).
struct SweepProbe {
  std::mutex m;
  std::vector<SweepRecord> runs;
};
inline std::atomic<SweepProbe*> sweep_probe{nullptr};

/// The dependencies of an in-order sweep, by position in the sweep (see the file comment).
struct SweepDag {
  std::vector<std::int32_t> node;        ///< the sweep's nodes, ascending
  std::vector<std::int32_t> next_start;  ///< position i's later neighbours: next[next_start[i] ..
  std::vector<std::int32_t> next;        ///<   next_start[i+1]), positions, ascending, distinct
  std::vector<std::int32_t> n_earlier;   ///< number of position i's earlier neighbours
  std::size_t size() const { return node.size(); }
  std::span<const std::int32_t> later(std::size_t i) const {
    return {next.data() + next_start[i], static_cast<std::size_t>(next_start[i + 1] - next_start[i])};
  }
};

/// The DAG of the in-order sweep over `nodes` (ascending, each < n) of a graph whose neighbours
/// of v are listed by for_neighbours(v, f), calling f(u) for each (repeats and u = v allowed;
/// neighbours outside the sweep are ignored). The relation must be symmetric: a position's
/// earlier neighbours are counted from its own list. Built on n_threads threads (for_neighbours
/// is called from several at once), the same DAG for every count.
template <class Neighbours>
SweepDag sweep_dag(std::size_t n, std::vector<std::int32_t> nodes, const Neighbours& for_neighbours, int n_threads = 1) {
  SweepDag d;
  d.node = std::move(nodes);
  const std::size_t m = d.node.size();
  std::vector<std::int32_t> position(n, -1);
  for (std::size_t i = 0; i < m; ++i) position[static_cast<std::size_t>(d.node[i])] = static_cast<std::int32_t>(i);
  d.next_start.assign(m + 1, 0);
  d.n_earlier.assign(m, 0);
  // Each part of the positions lists its later neighbours apart; the lists are then joined in
  // order. A serial build was up to 0.2 s of the 2-thread smoothing stage (sphere966 L6).
  // (Four parts a thread: for_each_range runs fewer than two chunks a thread on one thread.)
  const std::size_t n_parts = 4 * static_cast<std::size_t>(std::clamp(n_threads, 1, 256));
  std::vector<std::vector<std::int32_t>> part(n_parts);
  for_each_chunk(m, std::max<std::size_t>(1, (m + n_parts - 1) / n_parts), n_threads,
                 [&](std::size_t c, std::size_t begin, std::size_t end) {
                   std::vector<std::int32_t> near;
                   for (std::size_t i = begin; i < end; ++i) {
                     near.clear();
                     for_neighbours(d.node[i], [&](std::int32_t u) {
                       const std::int32_t j = position[static_cast<std::size_t>(u)];
                       if (j >= 0 && j != static_cast<std::int32_t>(i)) near.push_back(j);
                     });
                     // (Lists that come ascending and distinct, as a mesh's neighbours do,
                     // are taken as they are.)
                     if (std::adjacent_find(near.begin(), near.end(), std::greater_equal<>{}) != near.end()) {
                       std::sort(near.begin(), near.end());
                       near.erase(std::unique(near.begin(), near.end()), near.end());
                     }
                     const auto later = std::upper_bound(near.begin(), near.end(), static_cast<std::int32_t>(i));
                     d.n_earlier[i] = static_cast<std::int32_t>(later - near.begin());
                     d.next_start[i + 1] = static_cast<std::int32_t>(near.end() - later);
                     part[c].insert(part[c].end(), later, near.end());
                   }
                 });
  for (std::size_t i = 0; i < m; ++i) d.next_start[i + 1] += d.next_start[i];
  d.next.reserve(static_cast<std::size_t>(d.next_start[m]));
  for (const auto& p : part) d.next.insert(d.next.end(), p.begin(), p.end());
  return d;
}

/// visit_dag's shares of the positions per thread. With one share per thread a thread that ran
/// dry took the lowest ready nodes of the other's share, where the other worked: 17% of the
/// visits, at twice the time a visit (cache lines moving between the cores; sphere966 L6, 2
/// threads). With 32 a thread moves to a share no other works on: 0.7% (experiments/sweep_profile
/// --shares, runs' CPU 2.72 -> 2.31 s, medians of 3 on a loaded machine).
inline std::size_t shares_per_thread = 32;

/// Runs visit(v, t) for every node of `dag` on n_threads threads (t in [0, n_threads), 0 = the
/// caller), each node once its earlier neighbours are done. The positions are cut into
/// consecutive shares; a thread visits the lowest ready positions of its share from a heap of
/// its own, without the lock, and when that has none, moves to a share with ready nodes that no
/// other thread works on, else helps with a few of another's. The lock was taken for every 5.5
/// visits, 395 k times a run (sphere966 L6, 2 threads, experiments/sweep_profile), now 20 k.
/// Waiting threads sleep. The first exception (of the lowest thread) is rethrown once all
/// threads have stopped; nodes not yet started are then not visited.

template <class Visit>
void visit_dag(const SweepDag& dag, int n_threads, const Visit& visit, SweepRecord* rec = nullptr,
               double* cost = nullptr) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  n_threads = std::max(1, n_threads);
  const std::size_t total = dag.size();
  std::unique_ptr<std::atomic<std::int32_t>[]> waiting(new std::atomic<std::int32_t>[total]);
  // One heap per share of the positions: the threads work apart in the mesh (fewer cache lines
  // bounce) until one runs dry and helps.
  using Heap = std::priority_queue<std::int32_t, std::vector<std::int32_t>, std::greater<>>;
  const std::size_t n_shares = std::max<std::size_t>(1, std::min(total, static_cast<std::size_t>(n_threads) * shares_per_thread));
  std::vector<Heap> ready(n_shares);
  std::size_t n_ready = 0;
  const auto share = [&](std::int32_t i) {
    return static_cast<std::size_t>(static_cast<std::uint64_t>(i) * n_shares / total);
  };
  for (std::size_t i = 0; i < total; ++i) {
    waiting[i].store(dag.n_earlier[i], std::memory_order_relaxed);
    if (dag.n_earlier[i] == 0) ready[share(static_cast<std::int32_t>(i))].push(static_cast<std::int32_t>(i)), ++n_ready;
  }
  std::mutex m;
  std::condition_variable cv;
  std::size_t done = 0;
  bool failed = false;
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n_threads));
  std::vector<double> waited(static_cast<std::size_t>(n_threads), 0.0), foreign_s(static_cast<std::size_t>(n_threads), 0.0), cpu(static_cast<std::size_t>(n_threads), 0.0);
  std::size_t n_batches = 0;
  // Each thread starts in its own part of the positions.
  std::vector<int> owner(n_shares, -1);
  std::vector<std::size_t> current(static_cast<std::size_t>(n_threads));
  for (int t = 0; t < n_threads; ++t) {
    current[static_cast<std::size_t>(t)] = static_cast<std::size_t>(t) * n_shares / static_cast<std::size_t>(n_threads);
    owner[current[static_cast<std::size_t>(t)]] = t;
  }
  std::atomic<bool> stop{false};      // an exception: the other threads stop too
  std::atomic<int> n_asleep{0};       // threads waiting for ready nodes
  const auto run = [&](int t) {
    // The ready nodes of the thread's current share sit in its own heap, taken and filled
    // without the lock; the lock is taken to publish nodes freed in other shares, to move to
    // another share, and when another thread sleeps, to hand it the upper half of the own heap.
    Heap own;
    std::vector<std::int32_t> mine, out;
    std::size_t my_done = 0;
    std::size_t& h = current[static_cast<std::size_t>(t)];
    Clock::time_point t0;
    if (rec) t0 = Clock::now(), cpu[static_cast<std::size_t>(t)] = -thread_cpu_seconds();
    struct CpuAtExit {
      double* slot;
      ~CpuAtExit() {
        if (slot) *slot += thread_cpu_seconds();
      }
    } cpu_at_exit{rec ? &cpu[static_cast<std::size_t>(t)] : nullptr};
    const auto visit_one = [&](std::int32_t i, bool foreign) {
      if (cost) {
        const auto a = Clock::now();
        visit(dag.node[static_cast<std::size_t>(i)], t);
        cost[i] = seconds(a, Clock::now());
        if (foreign) foreign_s[static_cast<std::size_t>(t)] += cost[i];
      } else {
        visit(dag.node[static_cast<std::size_t>(i)], t);
      }
      ++my_done;
      // acq_rel: the last earlier neighbour to finish sees the others' writes, and the thread
      // that takes the node (from its own heap, or under the mutex) sees them all.
      for (const std::int32_t j : dag.later(static_cast<std::size_t>(i)))
        if (waiting[static_cast<std::size_t>(j)].fetch_sub(1, std::memory_order_acq_rel) == 1) {
          if (!foreign && share(j) == h) {
            own.push(j);
          } else {
            out.push_back(j);
          }
        }
    };
    std::unique_lock lock(m);
    for (;;) {
      for (const std::int32_t j : out) ready[share(j)].push(j);
      n_ready += out.size();
      done += my_done;
      my_done = 0;
      if (done == total || failed) {
        cv.notify_all();
        return;
      }
      if (!out.empty() && n_asleep.load(std::memory_order_relaxed) > 0) cv.notify_one();
      out.clear();
      mine.clear();
      bool foreign = false;
      if (!own.empty()) {
        // Nodes handed to a sleeping thread stay in ready[h] until the own heap runs dry.
      } else if (owner[h] == t && !ready[h].empty()) {
        Heap& heap = ready[h];
        n_ready -= heap.size();
        while (!heap.empty()) own.push(heap.top()), heap.pop();
      } else {
        if (owner[h] == t) owner[h] = -1;
        std::size_t s = 0;
        while (s < n_shares && (ready[s].empty() || owner[s] >= 0)) ++s;
        if (s < n_shares) {
          h = s, owner[s] = t;
        } else {
          // Every share with ready nodes is another's: help there with a few of them.
          for (s = 0; s < n_shares && ready[s].empty(); ++s) {
          }
          if (s == n_shares) {
            if (rec) t0 = Clock::now();
            n_asleep.fetch_add(1, std::memory_order_relaxed);
            cv.wait(lock, [&] { return failed || done == total || n_ready > 0; });
            n_asleep.fetch_sub(1, std::memory_order_relaxed);
            if (rec) waited[static_cast<std::size_t>(t)] += seconds(t0, Clock::now());
            continue;
          }
          Heap& heap = ready[s];
          const std::size_t take = std::clamp<std::size_t>(heap.size() / 2, 1, 8);
          while (mine.size() < take && !heap.empty()) mine.push_back(heap.top()), heap.pop();
          n_ready -= mine.size();
          foreign = true;
        }
      }
      if (!foreign && own.empty()) {
        Heap& heap = ready[h];
        n_ready -= heap.size();
        while (!heap.empty()) own.push(heap.top()), heap.pop();
      }
      if (rec) {
        ++n_batches;
        if (foreign) rec->foreign += mine.size();
      }
      lock.unlock();
      try {
        for (const std::int32_t i : mine) visit_one(i, true);
        while (!own.empty() && !stop.load(std::memory_order_relaxed)) {
          const std::int32_t i = own.top();
          own.pop();
          visit_one(i, false);
          if (n_asleep.load(std::memory_order_relaxed) > 0 && (own.size() > 1 || !out.empty())) {
            // Another thread has nothing to do: publish what it may take (the upper half of
            // the own heap, away from where this thread works).
            std::vector<std::int32_t> keep;
            const std::size_t n_keep = (own.size() + 1) / 2;
            while (keep.size() < n_keep) keep.push_back(own.top()), own.pop();
            while (!own.empty()) out.push_back(own.top()), own.pop();
            for (const std::int32_t k : keep) own.push(k);
            break;
          }
          if (out.size() >= 64) break;
        }
      } catch (...) {
        stop.store(true);
        lock.lock();
        errors[static_cast<std::size_t>(t)] = std::current_exception();
        failed = true;
        cv.notify_all();
        return;
      }
      if (stop.load(std::memory_order_relaxed)) {
        lock.lock();
        cv.notify_all();
        return;
      }
      lock.lock();
    }
  };
  run_on_threads(n_threads, run);
  if (rec) {
    for (const double w : waited) rec->wait_s += w;
    for (const double c : cpu) rec->cpu_s += c;
    for (const double c : foreign_s) rec->foreign_s += c;
    rec->batches += n_batches;
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

/// Fills rec's depth and critical_s: the DAG's longest path by node count and by cost[i].
inline void critical_path(const SweepDag& dag, const double* cost, SweepRecord& rec) {
  std::vector<std::int32_t> depth(dag.size(), 1);
  std::vector<double> time(dag.size(), 0.0);
  for (std::size_t i = 0; i < dag.size(); ++i) {
    time[i] += cost[i];
    rec.depth = std::max(rec.depth, static_cast<std::size_t>(depth[i]));
    rec.critical_s = std::max(rec.critical_s, time[i]);
    for (const std::int32_t j : dag.later(i)) {
      depth[static_cast<std::size_t>(j)] = std::max(depth[static_cast<std::size_t>(j)], depth[i] + 1);
      time[static_cast<std::size_t>(j)] = std::max(time[static_cast<std::size_t>(j)], time[i]);
    }
  }
  for (std::size_t k = 0; k < rec.block_sizes.size(); ++k) {
    const std::size_t b = rec.block_sizes[k], n_blocks = (dag.size() + b - 1) / b;
    std::vector<double> start(n_blocks, 0.0);
    for (std::size_t blk = 0; blk < n_blocks; ++blk) {
      double t = start[blk];
      for (std::size_t i = blk * b; i < std::min(dag.size(), (blk + 1) * b); ++i) t += cost[i];
      rec.block_critical_s[k] = std::max(rec.block_critical_s[k], t);
      for (std::size_t i = blk * b; i < std::min(dag.size(), (blk + 1) * b); ++i)
        for (const std::int32_t j : dag.later(i))
          if (static_cast<std::size_t>(j) / b != blk) start[static_cast<std::size_t>(j) / b] = std::max(start[static_cast<std::size_t>(j) / b], t);
    }
  }
}

/// An in-order sweep over `nodes` (ascending), to be run once or repeatedly: on one thread (or
/// for fewer than `min_nodes` nodes) run() visits them in that order, on several as the DAG
/// allows; the visits see the same numbers either way (see the file comment). The bar was 1024
/// while each parallel call started its threads; with the pool (core/worker_pool.hpp) the
/// untangling's small sweeps pay from 128 nodes: fandisk L5 on two threads 17.08-19.00 s
/// against 18.17-21.10 s with 1024 (five alternating rounds; 32 no better than 128).
class OrderedSweep {
 public:
  template <class Neighbours>
  OrderedSweep(std::vector<std::int32_t> nodes, std::size_t n, int n_threads, const Neighbours& for_neighbours,
               std::size_t min_nodes = 128)
      : n_threads_(std::max(1, n_threads)) {
    const bool probe = sweep_probe.load(std::memory_order_relaxed) != nullptr;
    const auto a = std::chrono::steady_clock::now();
    if ((n_threads_ > 1 || probe) && nodes.size() >= min_nodes) {
      dag_ = sweep_dag(n, std::move(nodes), for_neighbours, n_threads_);
    } else {
      n_threads_ = 1;
      dag_.node = std::move(nodes);
    }
    build_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
  }
  std::size_t size() const { return dag_.size(); }
  int n_threads() const { return n_threads_; }
  /// visit(v, t) for every node, t the thread (0 = the caller).
  template <class Visit> void run(const Visit& visit) const {
    if (SweepProbe* probe = sweep_probe.load(std::memory_order_relaxed)) return run_measured(visit, *probe);
    if (n_threads_ == 1) {
      for (const std::int32_t v : dag_.node) visit(v, 0);
    } else {
      visit_dag(dag_, n_threads_, visit);
    }
  }

 private:
  template <class Visit> void run_measured(const Visit& visit, SweepProbe& probe) const {
    using Clock = std::chrono::steady_clock;
    SweepRecord rec;
    rec.nodes = dag_.size();
    rec.edges = dag_.next.size();
    rec.threads = n_threads_;
    rec.build_s = std::exchange(build_s_, 0.0);
    std::vector<double> cost(dag_.size(), 0.0);
    const auto a = Clock::now();
    if (n_threads_ == 1) {
      rec.cpu_s = -thread_cpu_seconds();
      for (std::size_t i = 0; i < dag_.node.size(); ++i) {
        const auto b = Clock::now();
        visit(dag_.node[i], 0);
        cost[i] = std::chrono::duration<double>(Clock::now() - b).count();
      }
      rec.cpu_s += thread_cpu_seconds();
    } else {
      visit_dag(dag_, n_threads_, visit, &rec, cost.data());
    }
    rec.run_s = std::chrono::duration<double>(Clock::now() - a).count();
    for (const double c : cost) rec.visit_s += c;
    if (!dag_.next_start.empty()) critical_path(dag_, cost.data(), rec);
    const std::lock_guard lock(probe.m);
    probe.runs.push_back(rec);
  }

  SweepDag dag_;
  int n_threads_ = 1;
  mutable double build_s_ = 0.0;
};

}  // namespace febemesh
