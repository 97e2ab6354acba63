#pragma once
/// @file fork_join.hpp
/// ForkJoin: helper threads kept alive for repeated short fork-join sections inside allocation-free hot
/// loops (docs/architecture.md#models-and-workspaces), e.g. one PDDP belief step, which is called
/// thousands of times per solve and lasts milliseconds. Starting a std::thread allocates and costs tens
/// of microseconds, so the helpers are started once, on the first run that needs them, and then wait on
/// a condition variable; later runs only hand them a task, which does not allocate.
///
/// Ownership: one ForkJoin belongs to one calling thread at a time (typically inside that caller's
/// scratch space). Copying or moving yields a fresh ForkJoin with no helpers, so copies never share
/// threads. The destructor stops and joins the helpers.

#include <memory>
#include <type_traits>

namespace gpilqg {

class ForkJoin {
 public:
  ForkJoin();
  ~ForkJoin();
  ForkJoin(const ForkJoin&) noexcept;
  ForkJoin& operator=(const ForkJoin&) noexcept;

  /// Calls task(worker, workers) for worker = 0 .. workers-1: worker 0 on the calling thread, the
  /// others on helper threads. Returns when every call has returned; if any threw, rethrows the
  /// exception of the lowest-numbered worker that threw. workers <= 1: task(0, 1) here, no threads.
  /// Each worker picks its share of the work from its index (or from a shared atomic counter).
  template <class Task>
  void run(int workers, Task&& task) {
    if (workers <= 1) {
      task(0, 1);
      return;
    }
    using Callable = std::remove_reference_t<Task>;
    const Function call = [](void* context, int worker, int count) {
      (*static_cast<Callable*>(context))(worker, count);
    };
    run_erased(workers, call, const_cast<void*>(static_cast<const void*>(&task)));
  }

  /// Helper threads started so far (workers - 1 of the largest run).
  int helpers() const;

 private:
  using Function = void (*)(void* context, int worker, int workers);
  void run_erased(int workers, Function function, void* context);

  struct Shared;
  std::unique_ptr<Shared> shared_;
};

}  // namespace gpilqg
