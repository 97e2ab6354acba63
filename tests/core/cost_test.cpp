// Quadratic and tracking costs: derivatives against central differences, the reference problem's
// zero-control cost (500 pi^2, tests/reference/ilqr_cartpole/README.md), and validation.

#include <numbers>

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/integrator.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

Matrix random_spd(int n, unsigned seed) {
  const Matrix L = test::random_vector(n * n, -1.0, 1.0, seed).reshaped(n, n);
  return L * L.transpose() + 0.1 * Matrix::Identity(n, n);
}

QuadraticCost reference_cost() {
  // The reference problem: dt = 0.05, Q = 0, R = 0.1, Qf = diag(100, 100, 1000, 100), goal upright.
  Vector goal(4);
  goal << 0, 0, std::numbers::pi, 0;
  return QuadraticCost(0.05, Matrix::Zero(4, 4), Matrix::Constant(1, 1, 0.1),
                       Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(), goal);
}

TEST(Cost, ZeroControlCostOfTheReferenceProblemIs500PiSquared) {
  // All-zero controls leave the cart-pole hanging at rest, so only the terminal cost remains:
  // 0.5 * 1000 * pi^2 = 4934.80220054468 (the oracle's value).
  const QuadraticCost cost = reference_cost();
  IntegratedStepModel model(std::make_shared<CartPole>(), Integrator::Euler, 0.05);
  Vector x = Vector::Zero(4);
  const Vector u = Vector::Zero(1);
  double J = 0.0;
  for (int t = 0; t < 100; ++t) {
    J += cost.stage(t, x, u);
    x = model.next(x, u);
  }
  J += cost.terminal(x);
  EXPECT_NEAR(J, 4934.80220054468, 1e-9);
  EXPECT_NEAR(J, 500.0 * std::numbers::pi * std::numbers::pi, 1e-9);
}

TEST(Cost, StageAndTerminalDerivativesMatchCentralDifferences) {
  const int n = 5, m = 2, T = 7;
  const Matrix x_ref = test::random_vector(n * (T + 1), -1, 1, 1).reshaped(n, T + 1);
  const Matrix u_ref = test::random_vector(m * T, -1, 1, 2).reshaped(m, T);
  const auto tracking = QuadraticCost::tracking(0.1, random_spd(n, 3), random_spd(m, 4), random_spd(n, 5),
                                                x_ref, u_ref);
  const QuadraticCost regulation(0.1, random_spd(n, 6), random_spd(m, 7), random_spd(n, 8),
                                 test::random_vector(n, -1, 1, 9));
  for (const QuadraticCost* cost : {&tracking, &regulation}) {
    for (int t : {0, 3, T - 1}) {
      const Vector x = test::random_vector(n, -2, 2, 10 + t), u = test::random_vector(m, -2, 2, 20 + t);
      CostDerivatives d;
      const double value = cost->stage(t, x, u, &d);
      EXPECT_DOUBLE_EQ(value, d.value);
      auto as_vector = [](double v) { return Vector::Constant(1, v); };
      const Matrix lx = test::numeric_jacobian([&](const Vector& xs) { return as_vector(cost->stage(t, xs, u)); }, x, 1e-6);
      const Matrix lu = test::numeric_jacobian([&](const Vector& us) { return as_vector(cost->stage(t, x, us)); }, u, 1e-6);
      auto gradient_x = [&](const Vector& xs) { CostDerivatives g; cost->stage(t, xs, u, &g); return g.lx; };
      auto gradient_u = [&](const Vector& us) { CostDerivatives g; cost->stage(t, x, us, &g); return g.lu; };
      // Quadratics: central differences are exact up to round-off (~eps * |l| / h ~ 1e-9).
      EXPECT_MATRIX_NEAR(Matrix(d.lx.transpose()), lx, 1e-8);
      EXPECT_MATRIX_NEAR(Matrix(d.lu.transpose()), lu, 1e-8);
      EXPECT_MATRIX_NEAR(d.lxx, test::numeric_jacobian(gradient_x, x, 1e-6), 1e-8);
      EXPECT_MATRIX_NEAR(d.luu, test::numeric_jacobian(gradient_u, u, 1e-6), 1e-8);
      // l_ux = d(l_u)/dx (m x n).
      auto lu_of_x = [&](const Vector& xs) { CostDerivatives g; cost->stage(t, xs, u, &g); return g.lu; };
      EXPECT_MATRIX_NEAR(d.lux, test::numeric_jacobian(lu_of_x, x, 1e-6), 1e-8);
    }
    const Vector x = test::random_vector(n, -2, 2, 40);
    CostDerivatives d;
    cost->terminal(x, &d);
    auto terminal_gradient = [&](const Vector& xs) { CostDerivatives g; cost->terminal(xs, &g); return g.lx; };
    EXPECT_MATRIX_NEAR(Matrix(d.lx.transpose()),
                       test::numeric_jacobian([&](const Vector& xs) { return Vector::Constant(1, cost->terminal(xs)); }, x, 1e-6),
                       1e-8);
    EXPECT_MATRIX_NEAR(d.lxx, test::numeric_jacobian(terminal_gradient, x, 1e-6), 1e-8);
  }
}

TEST(Cost, TrackingUsesTheReferenceOfEachStep) {
  const Matrix x_ref = Matrix::Identity(2, 3);  // columns e1, e2, 0
  const Matrix u_ref = Matrix::Ones(1, 2);
  const auto cost = QuadraticCost::tracking(0.5, Matrix::Identity(2, 2), Matrix::Identity(1, 1),
                                            2.0 * Matrix::Identity(2, 2), x_ref, u_ref);
  EXPECT_DOUBLE_EQ(cost.stage(0, x_ref.col(0), u_ref.col(0)), 0.0);
  EXPECT_DOUBLE_EQ(cost.stage(1, x_ref.col(0), u_ref.col(1)), 0.5 * 0.5 * 2.0);  // |e1 - e2|^2 = 2
  EXPECT_DOUBLE_EQ(cost.terminal(x_ref.col(2)), 0.0);
  EXPECT_DOUBLE_EQ(cost.terminal(x_ref.col(0)), 0.5 * 2.0);
  // Past the end the final reference is held (receding-horizon windows run past the task).
  EXPECT_DOUBLE_EQ(cost.stage(5, x_ref.col(2), u_ref.col(1)), 0.0);
  EXPECT_DOUBLE_EQ(cost.terminal_at(1, x_ref.col(1)), 0.0);
  EXPECT_DOUBLE_EQ(cost.terminal_at(9, x_ref.col(0)), 1.0);
  EXPECT_THROW(cost.stage(-1, x_ref.col(0), u_ref.col(0)), std::out_of_range);
}

TEST(Cost, StraightLineReferenceRunsFromStartToGoal) {
  Vector x0(3), goal(3);
  x0 << 0, 0, 5;
  goal << 4, 0, 5;
  const Matrix ref = straight_line_reference(x0, goal, 80);
  ASSERT_EQ(ref.cols(), 81);
  EXPECT_MATRIX_NEAR(ref.col(0), x0, 0.0);
  EXPECT_MATRIX_NEAR(ref.col(80), goal, 1e-15);
  EXPECT_MATRIX_NEAR(ref.col(40), Vector(Eigen::Vector3d(2, 0, 5)), 1e-15);
  EXPECT_THROW(straight_line_reference(x0, goal, 0), std::invalid_argument);
}

TEST(Cost, RejectsBadWeightsAndReferencesNamingTheField) {
  const Matrix I2 = Matrix::Identity(2, 2), I1 = Matrix::Identity(1, 1);
  Matrix asymmetric = I2;
  asymmetric(0, 1) = 1.0;
  try {
    QuadraticCost(0.1, asymmetric, I1, I2, Vector::Zero(2));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'Q'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(QuadraticCost(0.1, I2, I1, Matrix::Identity(3, 3), Vector::Zero(2)), std::invalid_argument);
  EXPECT_THROW(QuadraticCost(0.1, I2, I1, I2, Vector::Zero(3)), std::invalid_argument);
  EXPECT_THROW(QuadraticCost(-0.1, I2, I1, I2, Vector::Zero(2)), std::invalid_argument);
  EXPECT_THROW(QuadraticCost::tracking(0.1, I2, I1, I2, Matrix::Zero(2, 5), Matrix::Zero(1, 5)),
               std::invalid_argument);  // u_ref needs T = 4 columns
}

}  // namespace
}  // namespace gpilqg
