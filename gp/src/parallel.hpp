#pragma once
/// @file parallel.hpp
/// Internal: the two ways the GP code splits work over threads (the machine has 2 cores).

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace gpilqg::gp::detail {

/// Runs first() here and second() on another thread when `parallel`, else both in sequence.
template <class First, class Second>
void run_pair(bool parallel, First&& first, Second&& second) {
  if (!parallel) {
    first();
    second();
    return;
  }
  std::exception_ptr error;
  std::thread helper([&] {
    try {
      second();
    } catch (...) {
      error = std::current_exception();
    }
  });
  first();
  helper.join();
  if (error) std::rethrow_exception(error);
}

/// Calls task(worker, workers) on `workers` = min(threads, max_workers) threads (the calling thread
/// is worker 0); each task picks its share of the work from its index. Rethrows the first exception.
template <class Task>
void run_workers(int threads, int max_workers, Task&& task) {
  const int workers = std::max(1, std::min(threads, max_workers));
  if (workers == 1) {
    task(0, 1);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
  std::vector<std::thread> helpers;
  for (int w = 1; w < workers; ++w)
    helpers.emplace_back([&, w] {
      try {
        task(w, workers);
      } catch (...) {
        errors[static_cast<std::size_t>(w)] = std::current_exception();
      }
    });
  try {
    task(0, workers);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& h : helpers) h.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace gpilqg::gp::detail
