#pragma once
/// @file same_run_results.hpp
/// The equality of two runs' results in every number that does not measure wall-clock time, bit for
/// bit: a resumed run (run_resume_test.cpp) and a run executed unit by unit in another order
/// (run_units_test.cpp) must each equal the uninterrupted single-process run.

#include <gtest/gtest.h>

#include "gpilqg/experiments/run_experiment.hpp"

namespace gpilqg::test {

/// Every number of two runs that does not measure wall-clock time, bit for bit.
inline void expect_same_results(const RunResults& resumed, const RunResults& reference) {
  ASSERT_EQ(resumed.tasks.size(), reference.tasks.size());
  for (std::size_t t = 0; t < reference.tasks.size(); ++t) {
    const TaskResults& a = resumed.tasks[t];
    const TaskResults& b = reference.tasks[t];
    ASSERT_EQ(a.algorithms, b.algorithms);
    EXPECT_EQ(a.slice.mean, b.slice.mean) << "figure-1 slice, task " << t;
    EXPECT_EQ(a.slice.std, b.slice.std) << "figure-1 slice, task " << t;
    for (std::size_t s = 0; s < b.seeds.size(); ++s) {
      for (std::size_t i = 0; i < b.algorithms.size(); ++i) {
        const AlgorithmRun& x = a.seeds[s][i];
        const AlgorithmRun& y = b.seeds[s][i];
        SCOPED_TRACE("task " + std::to_string(t) + ", seed index " + std::to_string(s) + ", " + y.name);
        EXPECT_EQ(x.converged_at, y.converged_at);
        EXPECT_EQ(x.data.x, y.data.x);
        EXPECT_EQ(x.data.u, y.data.u);
        EXPECT_EQ(x.data.x_next, y.data.x_next);
        EXPECT_EQ(x.data.iteration, y.data.iteration);
        ASSERT_EQ(x.iterations.size(), y.iterations.size());
        for (std::size_t k = 0; k < y.iterations.size(); ++k) {
          const IterationRecord& p = x.iterations[k];
          const IterationRecord& q = y.iterations[k];
          EXPECT_EQ(p.evaluation.costs, q.evaluation.costs) << "iteration " << k;
          EXPECT_EQ(p.evaluation.example.x, q.evaluation.example.x) << "iteration " << k;
          EXPECT_EQ(p.plan.policy.x_bar, q.plan.policy.x_bar) << "iteration " << k;
          EXPECT_EQ(p.plan.policy.u_bar, q.plan.policy.u_bar) << "iteration " << k;
          EXPECT_EQ(p.plan.policy.K, q.plan.policy.K) << "iteration " << k;
          EXPECT_EQ(p.plan.predicted_cost, q.plan.predicted_cost) << "iteration " << k;
          EXPECT_EQ(p.hyperparameters, q.hyperparameters) << "iteration " << k;
          EXPECT_EQ(p.policy_change, q.policy_change) << "iteration " << k;
          EXPECT_EQ(p.repeated, q.repeated) << "iteration " << k;
          EXPECT_EQ(p.data_rows, q.data_rows) << "iteration " << k;
        }
      }
    }
  }
}

}  // namespace gpilqg::test
