// DDP's reuse of the model Jacobians computed during the line search (StepModel::
// jacobians_nearly_free): the solve is the same, bit for bit, as the one that steps the nominal
// trajectory again in its derivative pass, and the derivative pass then never steps the model.

#include <numbers>

#include <gtest/gtest.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/integrator.hpp"
#include "cartpole_swingup.hpp"

namespace gpilqg {
namespace {

/// The cart-pole step, claiming cheap Jacobians or not, counting the steps with and without them.
class CountingModel final : public StepModel {
 public:
  CountingModel(bool jacobians_nearly_free)
      : inner_(std::make_shared<CartPole>(), Integrator::RK4, 0.05), nearly_free_(jacobians_nearly_free) {}
  int state_dim() const override { return inner_.state_dim(); }
  int control_dim() const override { return inner_.control_dim(); }
  double dt() const override { return inner_.dt(); }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians* jacobians, StepWorkspace&) const override {
    ++(jacobians != nullptr ? with_jacobians : without_jacobians);
    inner_.step(x, u, x_next, jacobians);
  }
  bool jacobians_nearly_free() const override { return nearly_free_; }

  mutable int with_jacobians = 0, without_jacobians = 0;

 private:
  IntegratedStepModel inner_;
  bool nearly_free_;
};

DdpResult swing_up(const StepModel& model) {
  const QuadraticCost cost = test::cartpole_swingup_cost(0.05, Matrix::Zero(4, 4));
  DdpProblem problem;
  problem.model = &model;
  problem.cost = &cost;
  problem.x0 = Vector::Zero(4);
  problem.horizon = 60;
  problem.u_min = Vector::Constant(1, -10.0);
  problem.u_max = Vector::Constant(1, 10.0);
  DdpOptions options;
  options.max_iterations = 200;
  options.line_search_steps = 1;       // full steps only, judged strictly: some are rejected, and
  options.min_reduction_ratio = 0.5;   // the next iteration starts from the same nominal
  return DdpSolver(options).solve(problem, Matrix::Zero(1, 60));
}

TEST(DdpJacobianReuse, GivesTheSameSolveWithoutSteppingTheNominalAgain) {
  const CountingModel stepping(false), reusing(true);
  const DdpResult a = swing_up(stepping);
  const DdpResult b = swing_up(reusing);
  ASSERT_GT(a.summary.iterations, 5);
  EXPECT_EQ(a.summary.termination, b.summary.termination);
  EXPECT_EQ(a.summary.iterations, b.summary.iterations);
  EXPECT_EQ(a.trajectory.x, b.trajectory.x);
  EXPECT_EQ(a.trajectory.u, b.trajectory.u);
  for (std::size_t t = 0; t < a.policy.K.size(); ++t) EXPECT_EQ(a.policy.K[t], b.policy.K[t]) << "t = " << t;
  EXPECT_EQ(a.policy.k, b.policy.k);
  EXPECT_EQ(a.nominal_cost, b.nominal_cost);
  EXPECT_EQ(a.expected_cost, b.expected_cost);

  // Stepping: a derivative pass (T steps with Jacobians) for the first nominal and for every
  // accepted candidate, none for an iteration that keeps its nominal; the rollouts step without.
  // Reusing: every step is a rollout step with Jacobians.
  int trials = 0, rejected = 0, accepted = 0;
  for (const auto& record : a.summary.trace) {
    trials += record.line_search_trials;
    (record.accepted ? accepted : rejected) += 1;
  }
  const int T = 60, rollouts = 1 + trials;  // the initial rollout and every line-search candidate
  EXPECT_GT(rejected, 0) << "the case should exercise an iteration that keeps its nominal";
  EXPECT_EQ(stepping.without_jacobians, rollouts * T);
  EXPECT_EQ(stepping.with_jacobians, (1 + accepted) * T);
  EXPECT_EQ(reusing.without_jacobians, 0);
  EXPECT_EQ(reusing.with_jacobians, rollouts * T);
  EXPECT_LT(reusing.with_jacobians + reusing.without_jacobians, stepping.with_jacobians + stepping.without_jacobians);
}

}  // namespace
}  // namespace gpilqg
