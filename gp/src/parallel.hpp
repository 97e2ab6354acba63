#pragma once
/// @file parallel.hpp
/// Internal: the ways the GP code splits work over threads (the machine has 2 cores), all on
/// ForkJoin (core/fork_join.hpp). These start their helpers per call, which suits work of
/// milliseconds and more (NLML evaluations, fits); a hot loop keeps its own ForkJoin instead
/// (MomentMatch::fork_join).

#include <algorithm>
#include <atomic>
#include <exception>
#include <vector>

#include "gpilqg/core/fork_join.hpp"

namespace gpilqg::gp::detail {

/// Runs first() here and second() on another thread when `parallel`, else both in sequence.
template <class First, class Second>
void run_pair(bool parallel, First&& first, Second&& second) {
  if (!parallel) {
    first();
    second();
    return;
  }
  ForkJoin pool;
  pool.run(2, [&](int worker, int) {
    if (worker == 0)
      first();
    else
      second();
  });
}

/// Calls task(worker, workers) on `workers` = min(threads, max_workers) threads (the calling thread
/// is worker 0); each task picks its share of the work from its index. Rethrows the first exception.
template <class Task>
void run_workers(int threads, int max_workers, Task&& task) {
  ForkJoin pool;
  pool.run(std::max(1, std::min(threads, max_workers)), task);
}

/// Runs task(i) for every i in [0, count) on up to `threads` threads, each taking the next index
/// (so uneven tasks balance). Every task runs even if another throws; then the exception of the
/// lowest index is rethrown.
template <class Task>
void run_indexed(int count, int threads, Task&& task) {
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(std::max(count, 0)));
  std::atomic<int> next{0};
  run_workers(threads, count, [&](int, int) {
    for (int i = next++; i < count; i = next++) {
      try {
        task(i);
      } catch (...) {
        errors[static_cast<std::size_t>(i)] = std::current_exception();
      }
    }
  });
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace gpilqg::gp::detail
