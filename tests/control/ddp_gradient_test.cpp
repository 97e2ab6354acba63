// The engine's derivative of the merit with respect to the controls (the costate recursion through
// A, B, the cost and the diffusion columns) against central differences of the merit itself,
// on the nonlinear cart-pole with multiplicative noise, for every variant.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/integrator.hpp"
#include "cartpole_swingup.hpp"
#include "gpilqg/core/systems.hpp"
#include "linear_models.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// M(u) = l_T(x_T) + sum_t [l_t + 0.5 sum_i c_i' S_{t+1} c_i] along the open-loop rollout of u, with
/// c = sqrt(dt) [F, G] as the variant selects and S held fixed: the quantity whose gradient the engine
/// reports.
double merit(const StepModel& model, const Cost& cost, const Vector& x0, const Matrix& u,
             const std::vector<Matrix>& S, DdpVariant variant) {
  Vector x = x0, next(x0.size());
  double J = 0.0;
  DiffusionColumns d;
  const double dt = model.dt();
  for (int t = 0; t < u.cols(); ++t) {
    J += cost.stage(t, x, u.col(t));
    auto add = [&](const DiffusionColumns& cols) {
      for (int i = 0; i < cols.count(); ++i)
        J += 0.5 * dt * cols.columns.col(i).dot(S[static_cast<std::size_t>(t + 1)] * cols.columns.col(i));
    };
    if (variant != DdpVariant::ILQR) {
      model.noise(x, u.col(t), d, false);
      add(d);
    }
    if (variant == DdpVariant::RobustILQG) {
      model.uncertainty(x, u.col(t), d, false);
      add(d);
    }
    model.step(x, u.col(t), next);
    x = next;
  }
  return J + cost.terminal(x);
}

class MeritGradient : public ::testing::TestWithParam<DdpVariant> {};

TEST_P(MeritGradient, MatchesCentralDifferencesOnANonlinearSystem) {
  ActuatorNoise noise;
  noise.additive_std = Vector::Constant(1, 0.3);
  noise.multiplicative_std = Vector::Constant(1, 0.4);
  IntegratedStepModel model(make_system("cartpole", Preset::Simulator, {}, noise), Integrator::RK4, 0.05);
  const QuadraticCost cost = test::cartpole_swingup_cost(0.05, Matrix::Identity(4, 4));
  DdpProblem problem;
  problem.model = &model;
  problem.cost = &cost;
  problem.x0 = Vector::Zero(4);
  problem.horizon = 40;
  DdpOptions options;
  options.variant = GetParam();
  options.max_iterations = 3;  // stop early: the gradient is far from zero there
  DdpSolver solver(options);
  const DdpResult r = solver.solve(problem, Matrix::Constant(1, 40, 0.5));
  ASSERT_GT(r.gradient.cwiseAbs().maxCoeff(), 1e-3);

  const Matrix numeric = test::numeric_jacobian(
      [&](const Vector& flat) {
        return Vector::Constant(1, merit(model, cost, problem.x0, flat.reshaped(1, 40), r.value_hessians, GetParam()));
      },
      r.trajectory.u.reshaped(40, 1), 1e-6);
  // |M| ~ 1e3 and h = 1e-6: round-off ~ eps |M| / h ~ 2e-7, truncation ~ h^2 M''' negligible.
  EXPECT_TRUE(test::matrices_near(r.gradient.reshaped(1, 40), numeric, 2e-6, 1e-6));
}

INSTANTIATE_TEST_SUITE_P(AllVariants, MeritGradient,
                         ::testing::Values(DdpVariant::ILQR, DdpVariant::ILQG, DdpVariant::RobustILQG),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(MeritGradient, IncludesTheUncertaintyColumnsForRobustIlqg) {
  const Matrix A = Matrix::Identity(2, 2) + 0.1 * (Matrix(2, 2) << 0, 1, -1, -0.2).finished();
  const Matrix B = 0.1 * (Matrix(2, 1) << 0, 1).finished();
  test::LinearStepModel model(A, B, 0.1);
  model.multiplicative_std = 0.3;
  model.uncertainty_std = 0.8;
  const QuadraticCost cost(0.1, Matrix::Identity(2, 2), Matrix::Identity(1, 1), 5.0 * Matrix::Identity(2, 2),
                           Vector::Ones(2));
  DdpProblem problem;
  problem.model = &model;
  problem.cost = &cost;
  problem.x0 = Vector::Zero(2);
  problem.horizon = 15;
  DdpOptions options;
  options.variant = DdpVariant::RobustILQG;
  options.max_iterations = 1;
  DdpSolver solver(options);
  const DdpResult r = solver.solve(problem, Matrix::Constant(1, 15, 0.3));
  const Matrix numeric = test::numeric_jacobian(
      [&](const Vector& flat) {
        return Vector::Constant(1, merit(model, cost, problem.x0, flat.reshaped(1, 15), r.value_hessians,
                                         DdpVariant::RobustILQG));
      },
      r.trajectory.u.reshaped(15, 1), 1e-6);
  EXPECT_TRUE(test::matrices_near(r.gradient.reshaped(1, 15), numeric, 1e-7, 1e-6));
}

}  // namespace
}  // namespace gpilqg
