#pragma once
// The threads of the parallel stages, kept from one call to the next (issue 8).
//
// Every parallel stage runs f(t) on threads t = 0 .. n - 1 (t = 0 the caller) and waits for them
// all: ranges of a loop (parallel_ranges.hpp), the in-order and partitioned sweeps, refinement,
// balance, the MSH writer. A thread started and joined for each such call cost more than many
// of the calls' work: fandisk level 5 on two threads started 9,597 threads (strace), most for
// the untangling sweeps of a few hundred nodes, and the caller did 70% of the run's work
// (perf). Here the threads t >= 1 are a pool's, started once and then woken for each call. Who
// runs which t does not change what t computes, so every result is the same as before.

#include <functional>

namespace febemesh {

/// Runs f(t) for t = 0 .. n_threads - 1, t = 0 on the calling thread and every other t on a
/// thread of its own, all at the same time (a t may wait for another), and returns when all
/// have returned; then rethrows the exception of the lowest t that threw one. The threads are
/// the pool's when it is free; a call made while it is busy (from one of its threads, or from
/// another thread during a call) starts threads of its own for the call instead.
void run_on_threads(int n_threads, const std::function<void(int)>& f);

/// Threads the pool has started so far (for tests and benchmarks).
int pool_threads_started();

}  // namespace febemesh
