// The pieces of "plans that never lose" (best_start.hpp): the controls a policy applies in closed loop
// replay its trajectory open loop on the same model, and of several starts the solve begins at the
// cheapest on the model and ends no dearer than it.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "cartpole_swingup.hpp"
#include "gpilqg/control/best_start.hpp"
#include "gpilqg/control/policy.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {
namespace {

constexpr double kDt = 0.05;
constexpr int kHorizon = 60;

DdpProblem swing_up(const StepModel& model, const Cost& cost) {
  DdpProblem p;
  p.model = &model;
  p.cost = &cost;
  p.x0 = Vector::Zero(4);
  p.horizon = kHorizon;
  return p;
}

TEST(BestStart, ClosedLoopControlsReplayThePoliciesTrajectoryOpenLoop) {
  // A policy made on the simulator, run with its feedback on the real preset (a longer pole).
  const auto simulator = make_step_model(make_system("cartpole", Preset::Simulator), Integrator::RK4, kDt, 5);
  const auto real = make_step_model(make_system("cartpole", Preset::RealWorld), Integrator::RK4, kDt, 5);
  const QuadraticCost cost = test::cartpole_swingup_cost(kDt, Matrix::Zero(4, 4));
  DdpSolver solver;
  const DdpResult planned = solver.solve(swing_up(*simulator, cost), Matrix::Zero(1, kHorizon));
  const Matrix u = closed_loop_controls(*real, planned.policy, Vector::Zero(4));
  ASSERT_EQ(u.rows(), 1);
  ASSERT_EQ(u.cols(), kHorizon);
  PolicyRolloutSettings mean_step;
  mean_step.process_noise = false;
  std::mt19937_64 rng(1);
  const Matrix closed = rollout_policy(*real, planned.policy, Vector::Zero(4), mean_step, rng).trajectory.x;
  const Matrix open = rollout(*real, Vector::Zero(4), u).trajectory.x;
  EXPECT_EQ(open, closed);
  // The open-loop controls alone end elsewhere on the real preset: the feedback mattered.
  const Matrix drifted = rollout(*real, Vector::Zero(4), planned.policy.u_bar).trajectory.x;
  EXPECT_GT((drifted.col(kHorizon) - closed.col(kHorizon)).norm(), 0.1);
}

TEST(BestStart, SolvesFromTheCheapestStartAndEndsNoDearerThanIt) {
  const auto model = make_step_model(make_system("cartpole", Preset::Simulator), Integrator::RK4, kDt, 5);
  const QuadraticCost cost = test::cartpole_swingup_cost(kDt, Matrix::Zero(4, 4));
  DdpOptions options;
  options.max_iterations = 3;  // stops early: the starts end at different costs
  DdpSolver solver(options);
  const DdpProblem problem = swing_up(*model, cost);
  const Matrix zero = Matrix::Zero(1, kHorizon);
  DdpSolver converged;
  const Matrix good = converged.solve(problem, zero).policy.u_bar;
  const Matrix diverging = Matrix::Constant(1, kHorizon, 1e9);

  const BestStart best = solve_from_best_start(solver, problem, {zero, diverging, good});
  ASSERT_EQ(best.start_costs.size(), 3u);
  EXPECT_TRUE(std::isinf(best.start_costs[1]));
  EXPECT_LT(best.start_costs[2], best.start_costs[0]);
  // The start's cost is its rollout's: the same as the trajectory cost of an open-loop rollout.
  EXPECT_DOUBLE_EQ(best.start_costs[0], trajectory_cost(cost, rollout(*model, problem.x0, zero).trajectory));
  EXPECT_EQ(best.start, 2);
  EXPECT_DOUBLE_EQ(best.result.expected_cost, solver.solve(problem, good).expected_cost);
  EXPECT_LE(best.result.expected_cost, best.start_costs[2]);
  EXPECT_LT(best.result.expected_cost, solver.solve(problem, zero).expected_cost);
  EXPECT_EQ(solve_from_best_start(solver, problem, {good, good}).start, 0);
  EXPECT_THROW(solve_from_best_start(solver, problem, {}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
