/// Numerical faults of the solver and of rollouts (README "Reliability"): a DDP solve started far from
/// any solution, an initial rollout that diverges, derivatives that are NaN, and real-world rollouts
/// that blow up. Each ends with a status (termination reason, RolloutStatus) and never a NaN.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/control/policy.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {
namespace {

constexpr double kPi = 3.141592653589793;

/// Nothing in a result is NaN or inf (costs excepted where documented).
::testing::AssertionResult result_finite(const DdpResult& r) {
  if (!r.trajectory.x.allFinite()) return ::testing::AssertionFailure() << "trajectory x";
  if (!r.trajectory.u.allFinite()) return ::testing::AssertionFailure() << "trajectory u";
  if (!r.policy.x_bar.allFinite() || !r.policy.u_bar.allFinite() || !r.policy.k.allFinite())
    return ::testing::AssertionFailure() << "policy nominal";
  for (const Matrix& K : r.policy.K)
    if (!K.allFinite()) return ::testing::AssertionFailure() << "policy gain";
  for (const Matrix& S : r.value_hessians)
    if (!S.allFinite()) return ::testing::AssertionFailure() << "value Hessian";
  if (!r.gradient.allFinite()) return ::testing::AssertionFailure() << "gradient";
  if (!std::isfinite(r.summary.final_gradient_norm)) return ::testing::AssertionFailure() << "gradient norm";
  return ::testing::AssertionSuccess();
}

struct SwingUp {
  IntegratedStepModel model{make_system("cartpole"), Integrator::RK4, 0.05};
  QuadraticCost cost{0.05, Vector::Constant(4, 0.1).asDiagonal(), Matrix::Identity(1, 1) * 0.01,
                     Vector::Constant(4, 100.0).asDiagonal(), Vector((Vector(4) << 0, 0, kPi, 0).finished())};
  DdpProblem problem(const Vector& x0, int horizon) const {
    DdpProblem p;
    p.model = &model;
    p.cost = &cost;
    p.x0 = x0;
    p.horizon = horizon;
    return p;
  }
};

TEST(SolverFault, StartedFarFromAnySolutionRegularisesAndStopsWithAReason) {
  // Pole spinning at 40 rad/s, cart 50 m away at 30 m/s, pushed hard the wrong way for 3 s.
  const SwingUp s;
  const Vector x0 = (Vector(4) << 50.0, 30.0, 0.5, 40.0).finished();
  DdpOptions options;
  options.max_iterations = 150;
  DdpSolver solver(options);
  const DdpResult r = solver.solve(s.problem(x0, 60), Matrix::Constant(1, 60, -80.0));
  EXPECT_TRUE(result_finite(r));
  EXPECT_TRUE(std::isfinite(r.nominal_cost) && std::isfinite(r.expected_cost));
  EXPECT_LT(r.summary.final_cost, r.summary.initial_cost) << r.summary.report("ilqr");
  // Steps were rejected and the regularisation rose in response (from one iteration to the next).
  int rejected = 0, increases = 0;
  for (std::size_t i = 0; i < r.summary.trace.size(); ++i) {
    const DdpIteration& it = r.summary.trace[i];
    rejected += (it.accepted ? 0 : 1) + it.backward_failures;
    if (i > 0 && it.lambda > r.summary.trace[i - 1].lambda) ++increases;
  }
  EXPECT_GT(rejected, 0) << r.summary.report("ilqr");
  EXPECT_GT(increases, 0) << r.summary.report("ilqr");
  EXPECT_FALSE(to_string(r.summary.termination).empty());
  EXPECT_NE(r.summary.report("ilqr").find(std::string(to_string(r.summary.termination))), std::string::npos);
}

TEST(SolverFault, InitialControlsThatDivergeGiveAnInfiniteCostAndNoNaN) {
  const SwingUp s;
  DdpSolver solver;
  const DdpResult r = solver.solve(s.problem(Vector::Zero(4), 40), Matrix::Constant(1, 40, 1e200));
  EXPECT_EQ(r.summary.termination, DdpTermination::InitialRolloutDiverged);
  EXPECT_FALSE(converged(r.summary.termination));
  EXPECT_EQ(r.nominal_cost, std::numeric_limits<double>::infinity());  // documented, never 0 or NaN
  EXPECT_EQ(r.expected_cost, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(result_finite(r));
  EXPECT_LE(r.trajectory.x.cwiseAbs().maxCoeff(), kDivergedStateMagnitude);
  EXPECT_EQ(r.value_hessians.size(), 41u);
}

TEST(SolverFault, ATrajectoryTooSensitiveToItsControlsStallsInsteadOfConverging) {
  // The reference swing-up (cost_change at dt = 0.05 s) with Euler steps of 1 s: the line search
  // ends on a knife-edge trajectory whose cost is tiny and whose gradient is about 1e53.
  IntegratedStepModel model(make_system("cartpole"), Integrator::Euler, 1.0);
  const QuadraticCost cost(1.0, Vector::Zero(4).asDiagonal(), Matrix::Identity(1, 1) * 0.1,
                           Vector((Vector(4) << 100, 100, 1000, 100).finished()).asDiagonal(),
                           Vector((Vector(4) << 0, 0, kPi, 0).finished()));
  DdpProblem problem;
  problem.model = &model;
  problem.cost = &cost;
  problem.x0 = Vector::Zero(4);
  problem.horizon = 100;
  DdpOptions options;
  options.max_iterations = 1000;
  options.cost_tolerance = 1e-12;
  DdpSolver solver(options);
  const DdpResult r = solver.solve(problem, Matrix::Zero(1, 100));
  EXPECT_EQ(r.summary.termination, DdpTermination::Stalled) << r.summary.report("ilqr");
  EXPECT_FALSE(converged(r.summary.termination));
  EXPECT_FALSE(stationary(r.summary.final_gradient_norm, r.trajectory.u.cwiseAbs().maxCoeff(), r.summary.final_cost));
  EXPECT_TRUE(result_finite(r));
  EXPECT_TRUE(std::isfinite(r.nominal_cost) && std::isfinite(r.expected_cost));
  EXPECT_NE(r.summary.report("ilqr").find("stalled"), std::string::npos);
}

/// The cart-pole with Jacobians poisoned by NaN where |theta_dot| > 1 (the step itself is fine).
class NanJacobians final : public StepModel {
 public:
  int state_dim() const override { return inner_.state_dim(); }
  int control_dim() const override { return inner_.control_dim(); }
  double dt() const override { return inner_.dt(); }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians, StepWorkspace&) const override {
    inner_.step(x, u, x_next, jacobians);
    if (jacobians != nullptr && std::abs(x(3)) > 1.0) jacobians->A(2, 3) = std::numeric_limits<double>::quiet_NaN();
  }

 private:
  IntegratedStepModel inner_{make_system("cartpole"), Integrator::Euler, 0.05};
};

TEST(SolverFault, NanDerivativesAreABackwardFailureNeverANaNPolicy) {
  const NanJacobians model;
  const SwingUp s;
  DdpProblem p = s.problem((Vector(4) << 0, 0, 0, 3.0).finished(), 30);
  p.model = &model;
  DdpOptions options;
  options.max_iterations = 20;
  DdpSolver solver(options);
  const DdpResult r = solver.solve(p, Matrix::Zero(1, 30));
  EXPECT_EQ(r.summary.termination, DdpTermination::RegularizationLimit) << r.summary.report("ilqr");
  EXPECT_TRUE(r.summary.final_backward_failed);
  EXPECT_TRUE(result_finite(r));
  for (const Matrix& K : r.policy.K) EXPECT_TRUE(K.isZero(0.0));  // open loop, as documented
  // The nominal cost is the cost of the returned trajectory, summed in full.
  double direct = s.cost.terminal(r.trajectory.x.col(30));
  for (int t = 0; t < 30; ++t) direct += s.cost.stage(t, r.trajectory.x.col(t), r.trajectory.u.col(t));
  EXPECT_DOUBLE_EQ(r.nominal_cost, direct);
  EXPECT_TRUE(std::isfinite(r.expected_cost));
}

TEST(RolloutFault, HugeGainsOnTheRealCartpoleStopAtTheDivergenceBound) {
  // A policy with gains 1e6 on the real-world cart-pole with RK4: the states grow geometrically.
  IntegratedStepModel world(make_system("cartpole", Preset::RealWorld), Integrator::RK4, 0.05);
  const int T = 200;
  AffinePolicy policy;
  policy.x_bar = Matrix::Zero(4, T + 1);
  policy.u_bar = Matrix::Zero(1, T);
  policy.k = Matrix::Zero(1, T);
  policy.K.assign(T, Matrix::Constant(1, 4, 1e6));
  PolicyRolloutSettings settings;
  settings.process_noise = false;
  std::mt19937_64 rng(3);
  const PolicyRollout r = rollout_policy(world, policy, (Vector(4) << 0.01, 0, 0.1, 0).finished(), settings, rng);
  EXPECT_FALSE(r.finite);
  EXPECT_NE(r.status, RolloutStatus::Completed) << to_string(r.status);
  EXPECT_LT(r.steps_completed, T);
  EXPECT_TRUE(r.trajectory.x.allFinite());
  EXPECT_TRUE(r.trajectory.u.allFinite());
  EXPECT_LE(r.trajectory.x.cwiseAbs().maxCoeff(), kDivergedStateMagnitude);
  // The costs of what was returned stay finite (the point of stopping at the bound, not at overflow).
  const SwingUp s;
  double cost = 0.0;
  for (int t = 0; t < T; ++t) cost += s.cost.stage(t, r.trajectory.x.col(t), r.trajectory.u.col(t));
  EXPECT_TRUE(std::isfinite(cost));
}

TEST(RolloutFault, EachWayOfDivergingHasItsStatus) {
  IntegratedStepModel world(make_system("cartpole"), Integrator::RK4, 0.05);
  // A control so large that one step leaves the bound.
  RolloutResult r = rollout(world, Vector::Zero(4), Matrix::Constant(1, 10, 1e20));
  EXPECT_EQ(r.status, RolloutStatus::StateBoundExceeded);
  EXPECT_EQ(r.steps_completed, 0);
  EXPECT_TRUE(r.trajectory.x.isZero(0.0));
  // A control that overflows within the step.
  r = rollout(world, Vector::Zero(4), Matrix::Constant(1, 10, 1e308));
  EXPECT_EQ(r.status, RolloutStatus::NonFiniteState) << to_string(r.status);
  EXPECT_TRUE(r.trajectory.x.allFinite());
  // A controller that returns NaN after 3 steps: the NaN is never stored.
  const Controller broken = [](int t, const VectorCRef&, VectorRef u) {
    u.setConstant(t < 3 ? 0.5 : std::numeric_limits<double>::quiet_NaN());
  };
  r = closed_loop_rollout(world, Vector::Zero(4), 10, broken, RolloutNoise::None, Vector(), nullptr);
  EXPECT_EQ(r.status, RolloutStatus::NonFiniteControl);
  EXPECT_EQ(r.steps_completed, 3);
  EXPECT_TRUE(r.trajectory.u.allFinite());
  EXPECT_EQ(r.trajectory.u(0, 2), 0.5);
  EXPECT_EQ(r.trajectory.u(0, 3), 0.0);
  EXPECT_EQ(to_string(RolloutStatus::NonFiniteControl), "non_finite_control");
  // A custom bound, and the bound and x0 are checked.
  r = closed_loop_rollout(world, Vector::Zero(4), 10, broken, RolloutNoise::None, Vector(), nullptr, 1e-3);
  EXPECT_EQ(r.status, RolloutStatus::StateBoundExceeded);
  EXPECT_THROW(closed_loop_rollout(world, Vector::Zero(4), 10, broken, RolloutNoise::None, Vector(), nullptr, 0.0),
               std::invalid_argument);
  EXPECT_THROW(rollout(world, Vector::Constant(4, std::nan("")), Matrix::Zero(1, 3)), std::invalid_argument);
}

TEST(SolverFault, AnIterationCallbackThatSaysStopCancelsWithTheLastAcceptedTrajectory) {
  // DdpOptions::on_iteration sees every iteration in order; returning false ends the solve there, with
  // a finite result and termination Cancelled (how Ctrl-C reaches inside a solve from Python).
  const SwingUp s;
  DdpOptions options;
  options.max_iterations = 100;
  std::vector<int> seen;
  options.on_iteration = [&](const DdpIteration& record) {
    seen.push_back(record.iteration);
    return seen.size() < 3;
  };
  const DdpResult r = DdpSolver(options).solve(s.problem(Vector::Zero(4), 40), Matrix::Zero(1, 40));
  EXPECT_EQ(r.summary.termination, DdpTermination::Cancelled);
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(r.summary.iterations, 3);
  EXPECT_FALSE(converged(r.summary.termination));
  EXPECT_TRUE(result_finite(r));
  EXPECT_LT(r.summary.final_cost, r.summary.initial_cost);
}

}  // namespace
}  // namespace gpilqg
