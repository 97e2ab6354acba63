// Options validation, names, the summary's one-line report, the policy's clamping and distance, and
// the engine's status reporting on bad starts.

#include <gtest/gtest.h>

#include <limits>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

TEST(DdpOptions, DefaultsAreValidAndBadValuesNameTheField) {
  EXPECT_NO_THROW(DdpOptions{}.validate());
  auto expect_field = [](DdpOptions o, const char* field) {
    try {
      o.validate();
      ADD_FAILURE() << "expected an error for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  DdpOptions o;
  o.max_iterations = 0;
  expect_field(o, "max_iterations");
  o = {};
  o.lambda_factor = 1.0;
  expect_field(o, "lambda_factor");
  o = {};
  o.lambda_max = 1e-9;
  expect_field(o, "lambda_max");
  o = {};
  o.cost_tolerance = -1;
  expect_field(o, "cost_tolerance");
  o = {};
  o.max_seconds = std::nan("");
  expect_field(o, "max_seconds");
  o = {};
  o.min_reduction_ratio = 1.0;
  expect_field(o, "min_reduction_ratio");
  EXPECT_THROW(DdpSolver{o}, std::invalid_argument);
}

TEST(DdpOptions, NamesRoundTrip) {
  for (auto v : {DdpVariant::ILQR, DdpVariant::ILQG, DdpVariant::RobustILQG}) EXPECT_EQ(parse_variant(to_string(v)), v);
  for (auto r : {RegularizationTarget::ControlHessian, RegularizationTarget::ValueHessian})
    EXPECT_EQ(parse_regularization(to_string(r)), r);
  EXPECT_FALSE(parse_variant("pddp").has_value());
}

TEST(DdpSummary, ReportIsOneLineWithTheTermination) {
  DdpSummary s;
  s.termination = DdpTermination::GradientNorm;
  s.iterations = 12;
  const std::string line = s.report("ilqg");
  EXPECT_NE(line.find("ilqg: gradient_norm after 12 iterations"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_TRUE(converged(DdpTermination::CostChange));
  EXPECT_FALSE(converged(DdpTermination::RegularizationLimit));
}

TEST(DdpSummary, StationaryComparesTheGradientsFirstOrderEffectWithTheCost) {
  // |g|_inf max(|u|_inf, 1) <= 1e3 max(|J|, 1).
  EXPECT_TRUE(stationary(2e-8, 3.5, 0.645));      // the reference swing-up at its optimum
  EXPECT_TRUE(stationary(5.3, 9.5, 0.32));        // a stiff acrobot swing-up: ratio 50
  EXPECT_TRUE(stationary(500.0, 0.1, 0.2));       // both floors at 1: 500 <= 1000
  EXPECT_TRUE(stationary(1000.0, 2.0, -2.0));     // 2000 <= 2000
  EXPECT_FALSE(stationary(1000.0, 2.0, 1.5));     // 2000 > 1500
  EXPECT_FALSE(stationary(8.1e53, 0.04, 2.2e-3)); // the cart-pole at dt = 1 s
  EXPECT_FALSE(stationary(std::numeric_limits<double>::infinity(), 1.0, 1.0));
  EXPECT_FALSE(stationary(std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0));
  EXPECT_FALSE(stationary(0.0, 1.0, std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(converged(DdpTermination::Stalled));
  EXPECT_EQ(to_string(DdpTermination::Stalled), "stalled");
}

TEST(AffinePolicy, ClampsToTheLimitsAndMeasuresChange) {
  AffinePolicy p;
  p.x_bar = Matrix::Zero(2, 2);
  p.u_bar = Matrix::Constant(1, 1, 1.0);
  p.k = Matrix::Constant(1, 1, 0.5);
  p.K = {Matrix::Constant(1, 2, 2.0)};
  p.u_min = Vector::Constant(1, -2.0);
  p.u_max = Vector::Constant(1, 2.0);
  Vector u(1);
  p.control(0, Vector(Eigen::Vector2d(0.1, 0.0)), u);
  EXPECT_DOUBLE_EQ(u(0), 1.7);
  p.control(0, Vector(Eigen::Vector2d(5.0, 0.0)), u);
  EXPECT_DOUBLE_EQ(u(0), 2.0);
  p.control(0, Vector(Eigen::Vector2d(0.0, 0.0)), u, 0.0);
  EXPECT_DOUBLE_EQ(u(0), 1.0);
  AffinePolicy q = p;
  q.K[0](0, 1) = 2.25;
  EXPECT_DOUBLE_EQ(p.distance(q), 0.25);
}

TEST(DdpSolver, ADivergingInitialRolloutIsAStatusNotAnException) {
  FiniteDifferenceStepModel exploding(1, 1, 0.1, [](const Vector& x, const Vector& u, Vector& next) {
    next = x.array().square() + u.array();
  });
  const QuadraticCost cost(0.1, Matrix::Identity(1, 1), Matrix::Identity(1, 1), Matrix::Identity(1, 1), Vector::Zero(1));
  DdpProblem problem{&exploding, &cost, Vector::Constant(1, 10.0), 30, {}, {}};
  DdpSolver solver;
  const DdpResult r = solver.solve(problem, Matrix::Zero(1, 30));
  EXPECT_EQ(r.summary.termination, DdpTermination::InitialRolloutDiverged);
  EXPECT_TRUE(r.trajectory.x.allFinite());
}

TEST(DdpSolver, RejectsInconsistentProblemsNamingWhatIsWrong) {
  IntegratedStepModel model(make_system("cartpole"), Integrator::Euler, 0.05);
  const QuadraticCost cost(0.05, Matrix::Identity(4, 4), Matrix::Identity(1, 1), Matrix::Identity(4, 4), Vector::Zero(4));
  DdpSolver solver;
  DdpProblem p{&model, &cost, Vector::Zero(3), 10, {}, {}};
  EXPECT_THROW(solver.solve(p, Matrix::Zero(1, 10)), std::invalid_argument);
  p.x0 = Vector::Zero(4);
  EXPECT_THROW(solver.solve(p, Matrix::Zero(1, 9)), std::invalid_argument);
  p.u_min = Vector::Constant(1, 1.0);
  p.u_max = Vector::Constant(1, -1.0);
  try {
    solver.solve(p, Matrix::Zero(1, 10));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("u_min[0]"), std::string::npos) << e.what();
  }
}

TEST(DdpSolver, ValueHessianRegularisationReachesTheSameOptimum) {
  IntegratedStepModel model(make_system("cartpole"), Integrator::Euler, 0.05);
  Vector goal(4);
  goal << 0, 0, 3.141592653589793, 0;
  const QuadraticCost cost(0.05, Matrix::Zero(4, 4), Matrix::Constant(1, 1, 0.1),
                           Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(), goal);
  DdpProblem p{&model, &cost, Vector::Zero(4), 100, {}, {}};
  DdpOptions o;
  o.regularization = RegularizationTarget::ValueHessian;
  o.cost_tolerance = 1e-14;
  o.max_iterations = 1000;
  DdpSolver solver(o);
  const DdpResult r = solver.solve(p, Matrix::Zero(1, 100));
  EXPECT_NEAR(r.nominal_cost, 0.645046921446, 1e-8) << r.summary.report("ilqr/value");
}

}  // namespace
}  // namespace gpilqg
