// Euler and RK4 steps: Jacobians against central differences for both systems, RK4 against the
// closed-form 4th-order Taylor polynomial of a linear system, convergence order, sub-steps, and
// energy conservation of the frictionless cart-pole.

#include <cmath>
#include <tuple>

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// xdot = F x + G u with analytic Jacobians: a system whose exact RK4 step is known in closed form.
class LinearDynamics final : public Dynamics {
 public:
  LinearDynamics(Matrix F, Matrix G) : F_(std::move(F)), G_(std::move(G)) {
    for (int i = 0; i < F_.rows(); ++i) states_.push_back({"s" + std::to_string(i), "-"});
    for (int j = 0; j < G_.cols(); ++j) controls_.push_back({"c" + std::to_string(j), "-"});
  }
  const std::string& name() const override { return name_; }
  const std::vector<Quantity>& states() const override { return states_; }
  const std::vector<Quantity>& controls() const override { return controls_; }
  std::vector<Parameter> parameters() const override { return {}; }
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jac) const override {
    xdot = F_ * x + G_ * u;
    if (jac) {
      jac->fx = F_;
      jac->fu = G_;
    }
  }

 private:
  std::string name_ = "linear";
  Matrix F_, G_;
  std::vector<Quantity> states_, controls_;
};

TEST(Integrator, Rk4OnALinearSystemIsTheFourthOrderTaylorPolynomialOfTheExponential) {
  // For xdot = F x + G u with u held, RK4 gives x' = P(hF) x + h Q(hF) G u with
  // P(M) = I + M + M^2/2 + M^3/6 + M^4/24 and Q(M) = I + M/2 + M^2/6 + M^3/24.
  const Matrix F = test::random_vector(9, -1.0, 1.0, 3).reshaped(3, 3);
  const Matrix G = test::random_vector(6, -1.0, 1.0, 4).reshaped(3, 2);
  const double h = 0.1;
  IntegratedStepModel model(std::make_shared<LinearDynamics>(F, G), Integrator::RK4, h);
  const Matrix M = h * F, I = Matrix::Identity(3, 3);
  const Matrix P = I + M + M * M / 2.0 + M * M * M / 6.0 + M * M * M * M / 24.0;
  const Matrix Q = I + M / 2.0 + M * M / 6.0 + M * M * M / 24.0;

  const Vector x = test::random_vector(3, -1.0, 1.0, 5), u = test::random_vector(2, -1.0, 1.0, 6);
  Vector x_next(3);
  StepJacobians jac;
  model.step(x, u, x_next, &jac);
  EXPECT_MATRIX_NEAR(x_next, Vector(P * x + h * Q * G * u), 1e-14);
  EXPECT_MATRIX_NEAR(jac.A, P, 1e-14);
  EXPECT_MATRIX_NEAR(jac.B, Matrix(h * Q * G), 1e-14);
}

TEST(Integrator, EulerStepIsXPlusDtF) {
  auto cp = std::make_shared<CartPole>();
  IntegratedStepModel model(cp, Integrator::Euler, 0.02);
  const Vector x = test::random_vector(4, -1.0, 1.0, 8), u = Vector::Constant(1, 0.4);
  EXPECT_MATRIX_NEAR(model.next(x, u), Vector(x + 0.02 * cp->f(x, u)), 0.0);
}

// Both systems x both integrators x {1, 3} sub-steps: A and B against central differences of the
// step itself. The step is smooth with |phi'''| of order dt (10 or less); h = 1e-6 gives truncation
// ~1e-12 and round-off ~1e-10, so 1e-7 is a safe bound that still catches a missing chain-rule term.
using StepCase = std::tuple<std::string, Integrator, int>;
class StepJacobianTest : public ::testing::TestWithParam<StepCase> {};

TEST_P(StepJacobianTest, MatchesCentralDifferencesAtRandomPoints) {
  const auto& [system, integrator, substeps] = GetParam();
  auto dynamics = make_system(system, Preset::RealWorld);
  IntegratedStepModel model(dynamics, integrator, 0.05, substeps);
  const int n = model.state_dim(), m = model.control_dim();
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Vector x = test::random_vector(n, -1.5, 1.5, seed);
    const Vector u = test::random_vector(m, 0.0, 4.0, seed + 100);
    Vector x_next(n);
    StepJacobians jac;
    model.step(x, u, x_next, &jac);
    const Matrix A = test::numeric_jacobian([&](const Vector& xs) { return model.next(xs, u); }, x, 1e-6);
    const Matrix B = test::numeric_jacobian([&](const Vector& us) { return model.next(x, us); }, u, 1e-6);
    EXPECT_TRUE(test::matrices_near(jac.A, A, 1e-7, 1e-7)) << system << " seed " << seed;
    EXPECT_TRUE(test::matrices_near(jac.B, B, 1e-7, 1e-7)) << system << " seed " << seed;
    EXPECT_MATRIX_NEAR(x_next, model.next(x, u), 0.0);  // the Jacobian path does not change the step
  }
}

INSTANTIATE_TEST_SUITE_P(
    BothSystemsBothIntegrators, StepJacobianTest,
    ::testing::Combine(::testing::Values("cartpole", "quadrotor"),
                       ::testing::Values(Integrator::Euler, Integrator::RK4), ::testing::Values(1, 3)),
    [](const auto& info) {
      return std::get<0>(info.param) + "_" + std::string(to_string(std::get<1>(info.param))) + "_" +
             std::to_string(std::get<2>(info.param)) + "substeps";
    });

TEST(Integrator, SubstepsEqualRepeatedShorterSteps) {
  auto cp = make_system("cartpole");
  IntegratedStepModel split(cp, Integrator::RK4, 0.06, 3);
  IntegratedStepModel single(cp, Integrator::RK4, 0.02);
  const Vector x = test::random_vector(4, -1.0, 1.0, 11), u = Vector::Constant(1, 1.5);
  Vector y = x;
  StepJacobians j, total;
  Matrix A = Matrix::Identity(4, 4), B = Matrix::Zero(4, 1);
  for (int s = 0; s < 3; ++s) {
    Vector next(4);
    single.step(y, u, next, &j);
    A = j.A * A;
    B = j.A * B + j.B;
    y = next;
  }
  Vector z(4);
  split.step(x, u, z, &total);
  EXPECT_MATRIX_NEAR(z, y, 1e-15);
  EXPECT_MATRIX_NEAR(total.A, A, 1e-14);
  EXPECT_MATRIX_NEAR(total.B, B, 1e-14);
}

TEST(Integrator, Rk4LocalErrorFallsWithTheFifthPowerOfTheStep) {
  // One step of length h against a 1000-sub-step reference over the same interval: the local error
  // of RK4 is O(h^5), so halving h divides it by ~32 (order log2(ratio) ~ 5). Euler's is O(h^2).
  auto cp = make_system("cartpole");
  Vector x0(4);
  x0 << 0.0, 0.5, 2.5, -1.0;
  const Vector u = Vector::Constant(1, 0.7);
  auto local_error = [&](Integrator integrator, double h) {
    const Vector reference = IntegratedStepModel(cp, Integrator::RK4, h, 1000).next(x0, u);
    return (IntegratedStepModel(cp, integrator, h).next(x0, u) - reference).norm();
  };
  for (double h : {0.05, 0.025}) {
    EXPECT_NEAR(std::log2(local_error(Integrator::RK4, h) / local_error(Integrator::RK4, h / 2)), 5.0, 0.3)
        << "h = " << h;
    EXPECT_NEAR(std::log2(local_error(Integrator::Euler, h) / local_error(Integrator::Euler, h / 2)), 2.0, 0.3)
        << "h = " << h;
  }
}

TEST(Integrator, Rk4ConservesCartPoleEnergyWithoutInputOrFriction) {
  // The criterion: energy drift below 1e-6 over 10 s at dt = 1e-3 (both presets).
  for (const auto& params : {CartPoleParameters::simulator(), CartPoleParameters::real_world()}) {
    auto cp = std::make_shared<CartPole>(params);
    IntegratedStepModel model(cp, Integrator::RK4, 1e-3);
    Vector x(4);
    x << 0.0, 0.3, 2.0, 1.5;  // a large swing with the cart moving
    const Vector u = Vector::Zero(1);
    const double e0 = cp->energy(x);
    double worst = 0.0;
    for (int k = 0; k < 10000; ++k) {
      x = model.next(x, u);
      worst = std::max(worst, std::abs(cp->energy(x) - e0));
    }
    EXPECT_LT(worst, 1e-6) << "initial energy " << e0 << " J";
    EXPECT_GT(e0, 10.0);  // the test is not trivially satisfied by a system at rest
  }
}

TEST(Integrator, ParsesNamesAndRejectsBadSettings) {
  EXPECT_EQ(parse_integrator("euler"), Integrator::Euler);
  EXPECT_EQ(parse_integrator("rk4"), Integrator::RK4);
  EXPECT_FALSE(parse_integrator("RK45").has_value());
  auto cp = make_system("cartpole");
  EXPECT_THROW(IntegratedStepModel(cp, Integrator::RK4, 0.0), std::invalid_argument);
  EXPECT_THROW(IntegratedStepModel(cp, Integrator::RK4, std::nan("")), std::invalid_argument);
  EXPECT_THROW(IntegratedStepModel(cp, Integrator::RK4, 0.01, 0), std::invalid_argument);
  EXPECT_THROW(IntegratedStepModel(nullptr, Integrator::RK4, 0.01), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
