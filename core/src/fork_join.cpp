/// @file fork_join.cpp
/// ForkJoin's helpers: each waits for a new generation of work, runs its share if its index is below
/// the run's worker count, and reports back. The run waits until every helper has reported.

#include "gpilqg/core/fork_join.hpp"

#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace gpilqg {

struct ForkJoin::Shared {
  std::mutex mutex;
  std::condition_variable start;  ///< helpers wait here for a new generation (or stop)
  std::condition_variable done;   ///< the run waits here until pending == 0
  unsigned long generation = 0;
  int pending = 0;                ///< helpers that have not reported for the current generation
  bool stop = false;
  Function function = nullptr;
  void* context = nullptr;
  int workers = 1;
  std::vector<std::exception_ptr> errors;  ///< per worker, sized when helpers start
  std::vector<std::thread> threads;        ///< helper h runs worker h + 1

  /// `seen`: the generation current when the helper was started (it must not run that one).
  void helper_loop(int worker, unsigned long seen) {
    for (;;) {
      Function f;
      void* c;
      int count;
      {
        std::unique_lock lock(mutex);
        start.wait(lock, [&] { return stop || generation != seen; });
        if (stop) return;
        seen = generation;
        f = function;
        c = context;
        count = workers;
      }
      std::exception_ptr error;
      if (worker < count) {
        try {
          f(c, worker, count);
        } catch (...) {
          error = std::current_exception();
        }
      }
      std::lock_guard lock(mutex);
      errors[static_cast<std::size_t>(worker)] = error;
      if (--pending == 0) done.notify_one();
    }
  }
};

ForkJoin::ForkJoin() = default;
ForkJoin::ForkJoin(const ForkJoin&) noexcept {}
ForkJoin& ForkJoin::operator=(const ForkJoin&) noexcept { return *this; }

ForkJoin::~ForkJoin() {
  if (!shared_) return;
  {
    std::lock_guard lock(shared_->mutex);
    shared_->stop = true;
  }
  shared_->start.notify_all();
  for (auto& t : shared_->threads) t.join();
}

int ForkJoin::helpers() const { return shared_ ? static_cast<int>(shared_->threads.size()) : 0; }

void ForkJoin::run_erased(int workers, Function function, void* context) {
  if (!shared_) shared_ = std::make_unique<Shared>();
  Shared& s = *shared_;
  // Start the missing helpers (the only allocation, on the first run with this many workers). A new
  // helper counts the current generation as seen, so it joins the next one like the others.
  const auto needed = static_cast<std::size_t>(workers - 1);
  if (s.threads.size() < needed) {
    std::lock_guard lock(s.mutex);
    s.errors.resize(needed + 1);
    while (s.threads.size() < needed) {
      const int worker = static_cast<int>(s.threads.size()) + 1;
      s.threads.emplace_back([&s, worker, seen = s.generation] { s.helper_loop(worker, seen); });
    }
  }
  {
    std::lock_guard lock(s.mutex);
    s.function = function;
    s.context = context;
    s.workers = workers;
    s.pending = static_cast<int>(s.threads.size());
    ++s.generation;
  }
  s.start.notify_all();
  std::exception_ptr first_error;
  try {
    function(context, 0, workers);
  } catch (...) {
    first_error = std::current_exception();
  }
  std::unique_lock lock(s.mutex);
  s.done.wait(lock, [&] { return s.pending == 0; });
  std::exception_ptr error = first_error;
  for (auto& helper_error : s.errors) {
    if (!error) error = helper_error;
    helper_error = nullptr;
  }
  lock.unlock();
  if (error) std::rethrow_exception(error);
}

}  // namespace gpilqg
