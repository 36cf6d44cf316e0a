#include "core/worker_pool.hpp"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace febemesh {
namespace {

thread_local bool on_pool_thread = false;

/// f(t) for t >= 1 on threads started for this call (the pool is busy).
void run_on_new_threads(int n_threads, const std::function<void(int)>& f, std::vector<std::exception_ptr>& errors) {
  std::vector<std::thread> threads;
  for (int t = 1; t < n_threads; ++t)
    threads.emplace_back([&, t] {
      try {
        f(t);
      } catch (...) {
        errors[static_cast<std::size_t>(t)] = std::current_exception();
      }
    });
  try {
    f(0);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (std::thread& th : threads) th.join();
}

class Pool {
 public:
  ~Pool() {
    {
      const std::lock_guard<std::mutex> hold(m_);
      stop_ = true;
    }
    start_.notify_all();
    for (std::thread& th : threads_) th.join();
  }

  /// run_on_threads on the pool's threads; false (nothing run) when the pool is busy.
  bool run(int n_threads, const std::function<void(int)>& f, std::vector<std::exception_ptr>& errors) {
    // (A call from within a call, on its caller's thread or the pool's, finds it busy too.)
    bool idle = false;
    if (on_pool_thread || !busy_.compare_exchange_strong(idle, true, std::memory_order_acquire)) return false;
    struct Release {
      std::atomic<bool>& busy;
      ~Release() { busy.store(false, std::memory_order_release); }
    } release{busy_};
    {
      const std::lock_guard<std::mutex> hold(m_);
      while (static_cast<int>(threads_.size()) < n_threads - 1) {
        const int t = static_cast<int>(threads_.size()) + 1;
        threads_.emplace_back([this, t] { serve(t); });
      }
      work_ = &f;
      errors_ = &errors;
      n_active_ = n_threads;
      pending_ = n_threads - 1;
      ++generation_;
    }
    start_.notify_all();
    try {
      f(0);
    } catch (...) {
      errors[0] = std::current_exception();
    }
    std::unique_lock<std::mutex> hold(m_);
    done_.wait(hold, [&] { return pending_ == 0; });
    work_ = nullptr;
    errors_ = nullptr;
    return true;
  }

  int started() {
    const std::lock_guard<std::mutex> hold(m_);
    return static_cast<int>(threads_.size());
  }

 private:
  /// Thread t's life: each call with t < n_active_ runs f(t) once.
  void serve(int t) {
    on_pool_thread = true;
    std::uint64_t seen = 0;
    std::unique_lock<std::mutex> hold(m_);
    for (;;) {
      start_.wait(hold, [&] { return stop_ || (generation_ != seen && t < n_active_); });
      if (stop_) return;
      seen = generation_;
      const std::function<void(int)>* f = work_;
      std::vector<std::exception_ptr>* errors = errors_;
      hold.unlock();
      try {
        (*f)(t);
      } catch (...) {
        (*errors)[static_cast<std::size_t>(t)] = std::current_exception();
      }
      hold.lock();
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::atomic<bool> busy_{false};  ///< a call is running (one at a time)
  std::mutex m_;     ///< the fields below
  std::condition_variable start_, done_;
  std::vector<std::thread> threads_;  ///< thread t at [t - 1]
  const std::function<void(int)>* work_ = nullptr;
  std::vector<std::exception_ptr>* errors_ = nullptr;
  std::uint64_t generation_ = 0;  ///< calls so far
  int n_active_ = 0;              ///< the current call's n_threads
  int pending_ = 0;               ///< its threads t >= 1 still running
  bool stop_ = false;
};

Pool& pool() {
  static Pool p;
  return p;
}

}  // namespace

void run_on_threads(int n_threads, const std::function<void(int)>& f) {
  if (n_threads <= 1) {
    f(0);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n_threads));
  if (!pool().run(n_threads, f, errors)) run_on_new_threads(n_threads, f, errors);
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

int pool_threads_started() { return pool().started(); }

}  // namespace febemesh
