// The cart-pole swing-up of tests/reference/ilqr_cartpole (Tassa's iLQG.m in Octave, cross-checked by
// a second iLQR to 1e-13): final cost to 1e-8 relative and the same final state, unconstrained
// (case C, J = 0.645046921446) and with |u| <= 2.5 (case E, J = 0.677802315918).

#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/integrator.hpp"
#include "cartpole_swingup.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

struct OracleCase {
  const char* folder;
  double reference_cost;  // summary.csv / README of the reference
  double limit;           // 0: unconstrained
};

class CartPoleOracle : public ::testing::TestWithParam<OracleCase> {};

TEST_P(CartPoleOracle, ReachesTheReferenceOptimumAndFinalState) {
  const OracleCase c = GetParam();
  IntegratedStepModel model(std::make_shared<CartPole>(), Integrator::Euler, 0.05);
  const QuadraticCost cost = test::cartpole_swingup_cost(0.05, Matrix::Zero(4, 4));
  DdpProblem problem;
  problem.model = &model;
  problem.cost = &cost;
  problem.x0 = Vector::Zero(4);
  problem.horizon = 100;
  if (c.limit > 0) {
    problem.u_min = Vector::Constant(1, -c.limit);
    problem.u_max = Vector::Constant(1, c.limit);
  }
  DdpOptions options;
  options.cost_tolerance = 1e-14;
  options.gradient_tolerance = 1e-9;
  options.max_iterations = 1000;
  DdpSolver solver(options);
  const DdpResult result = solver.solve(problem, Matrix::Zero(1, 100));
  SCOPED_TRACE(result.summary.report("ilqr"));
  std::printf("%s (reference %.12f)\n", result.summary.report("ilqr").c_str(), c.reference_cost);
  EXPECT_TRUE(converged(result.summary.termination)) << to_string(result.summary.termination);
  EXPECT_NEAR(result.nominal_cost, c.reference_cost, 1e-8 * c.reference_cost);
  EXPECT_DOUBLE_EQ(result.nominal_cost, result.expected_cost);  // no noise: the merit is the cost

  const auto dir = test::reference_dir() / "ilqr_cartpole" / c.folder;
  const Matrix x_ref = test::read_numeric_csv(dir / "x.csv");
  const Matrix u_ref = test::read_numeric_csv(dir / "u.csv");
  EXPECT_TRUE(test::matrices_near(result.trajectory.x.col(100), Vector(x_ref.row(100).transpose()), 1e-5))
      << "final state";
  EXPECT_TRUE(test::matrices_near(result.trajectory.u.transpose(), u_ref, 1e-4)) << "controls";
  if (c.limit > 0) {
    EXPECT_LE(result.trajectory.u.cwiseAbs().maxCoeff(), c.limit);
    const int on_limit = static_cast<int>((result.trajectory.u.cwiseAbs().array() >= c.limit - 1e-9).count());
    EXPECT_EQ(on_limit, 27);  // README: "27 of 100 steps on the limit"
  }
}

INSTANTIATE_TEST_SUITE_P(Reference, CartPoleOracle,
                         ::testing::Values(OracleCase{"C_primary_tight", 0.645046921446, 0.0},
                                           OracleCase{"E_primary_box_u2p5_tight", 0.677802315918, 2.5}),
                         [](const auto& info) { return info.param.limit > 0 ? "box_limited" : "unconstrained"; });

}  // namespace
}  // namespace gpilqg
