#pragma once
// Per-pass timings of DDP solves, read from the solver's own timers (DdpSummary::timings) and divided
// by the number of passes the solves actually ran. Shared by ddp_bench.cpp and pddp_bench.cpp.
//
// Passes run by one solve (control/src/ddp_solver.cpp, Engine::run):
//   derivative passes: one per iteration plus the final one at the returned trajectory;
//   backward passes:   one per iteration plus the rejected ones (backward_failures) plus the final gain pass;
//   forward passes:    the initial rollout plus every line-search trial.
// "One iteration" = one derivative pass + one backward pass + one forward pass.
//
// The solver's timers are wall-clock. On a shared machine wall-clock time overstates the work, so a
// caller can also pass the CPU time of each solve (measure_cpu_seconds); the CPU figures of the passes
// are then the wall-clock ones scaled by CPU time / wall time of the whole solves (exact when the
// passes are equally disturbed, which a single-threaded solve on a steadily loaded machine is).

#include <algorithm>
#include <ctime>
#include <string>

#include <benchmark/benchmark.h>

#include "gpilqg/control/ddp_solver.hpp"

namespace gpilqg::bench {

class DdpPassTiming {
 public:
  /// Runs `solve` (returning a DdpResult) and returns its result with the process CPU time it took.
  template <class Solve>
  static auto measure_cpu_seconds(Solve&& solve, double& cpu_seconds) {
    const std::clock_t start = std::clock();
    auto result = solve();
    cpu_seconds = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
    return result;
  }

  /// Accumulates the timers and pass counts of one solve, and its CPU time when known (>= 0).
  void add(const DdpResult& r, double cpu_seconds = -1.0) {
    const DdpTimings& t = r.summary.timings;
    if (cpu_seconds >= 0.0) {
      cpu_s_ += cpu_seconds;
      cpu_wall_s_ += t.total_s;
    }
    total_s_ += t.total_s;
    derivatives_s_ += t.derivatives_s;
    backward_s_ += t.backward_s;
    forward_s_ += t.forward_s;
    iterations_ += r.summary.iterations;
    derivative_passes_ += r.summary.iterations + 1;
    backward_passes_ += 1;
    forward_passes_ += 1;
    for (const auto& it : r.summary.trace) {
      backward_passes_ += 1 + it.backward_failures;
      forward_passes_ += it.line_search_trials;
    }
  }

  /// Writes the counters derivatives_<unit>, backward_<unit>, forward_<unit>, one_iteration_<unit> (per
  /// pass) and solver_<unit>_per_iteration (whole solve / iterations); `scale` converts seconds to `unit`.
  void report(benchmark::State& state, double scale, const char* unit) const {
    const std::string u(unit);
    const double derivatives = scale * derivatives_s_ / static_cast<double>(std::max(derivative_passes_, 1L));
    const double backward = scale * backward_s_ / static_cast<double>(std::max(backward_passes_, 1L));
    const double forward = scale * forward_s_ / static_cast<double>(std::max(forward_passes_, 1L));
    state.counters["derivatives_" + u] = derivatives;
    state.counters["backward_" + u] = backward;
    state.counters["forward_" + u] = forward;
    state.counters["one_iteration_" + u] = derivatives + backward + forward;
    state.counters["solver_" + u + "_per_iteration"] = scale * total_s_ / static_cast<double>(std::max(iterations_, 1L));
    if (cpu_wall_s_ > 0.0) {
      const double cpu_fraction = cpu_s_ / cpu_wall_s_;
      state.counters["cpu_fraction"] = cpu_fraction;
      state.counters["cpu_derivatives_" + u] = cpu_fraction * derivatives;
      state.counters["cpu_backward_" + u] = cpu_fraction * backward;
      state.counters["cpu_forward_" + u] = cpu_fraction * forward;
      state.counters["cpu_one_iteration_" + u] = cpu_fraction * (derivatives + backward + forward);
    }
  }

  long forward_passes() const { return forward_passes_; }
  long iterations() const { return iterations_; }

 private:
  double cpu_s_ = 0.0, cpu_wall_s_ = 0.0;
  double total_s_ = 0.0, derivatives_s_ = 0.0, backward_s_ = 0.0, forward_s_ = 0.0;
  long iterations_ = 0, derivative_passes_ = 0, backward_passes_ = 0, forward_passes_ = 0;
};

}  // namespace gpilqg::bench
