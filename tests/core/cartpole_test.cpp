// Cart-pole: the reference step of tests/reference/ilqr_cartpole (Octave oracle), analytic Jacobians
// against central differences, the presets and parameter validation.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/integrator.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

TEST(CartPole, EulerStepMatchesReferenceOracle) {
  // tests/reference/ilqr_cartpole/README.md, "Unit checks" (Tassa's iLQG.m in Octave, Euler dt = 0.05).
  auto model = IntegratedStepModel(std::make_shared<CartPole>(), Integrator::Euler, 0.05);
  Vector x(4), u(1);
  x << 0.3, -0.2, 2.0, 0.7;
  u << 1.3;
  Vector x_next(4);
  StepJacobians jac;
  model.step(x, u, x_next, &jac);

  Vector expected_next(4);
  expected_next << 0.29, -0.25382463930283294, 2.035, 0.23159065876783819;
  Matrix expected_A(4, 4);
  expected_A << 1, 0.05, 0, 0,                                   //
      0, 1, -0.20338185844990456, 0.034842380091111659,          //
      0, 0, 1, 0.05,                                             //
      0, 0, 0.070540700303480461, 1.0144995462526891;
  Matrix expected_B(4, 1);
  expected_B << 0, 0.02736993817047843, 0, 0.011389913186135482;

  EXPECT_MATRIX_NEAR(x_next, expected_next, 1e-12);
  EXPECT_MATRIX_NEAR(jac.A, expected_A, 1e-12);
  EXPECT_MATRIX_NEAR(jac.B, expected_B, 1e-12);
}

TEST(CartPole, AnalyticJacobiansMatchCentralDifferencesAtRandomPoints) {
  for (const auto& params : {CartPoleParameters::simulator(), CartPoleParameters::real_world(),
                             CartPoleParameters{0.7, 0.3, 0.5, 9.81}}) {
    const CartPole cp(params);
    for (unsigned seed = 0; seed < 25; ++seed) {
      const Vector x = test::random_vector(4, -4.0, 4.0, seed);
      const Vector u = test::random_vector(1, -10.0, 10.0, 1000 + seed);
      DynamicsJacobians jac;
      Vector xdot(4);
      cp.evaluate(x, u, xdot, &jac);
      const Matrix fx = test::numeric_jacobian([&](const Vector& xs) { return cp.f(xs, u); }, x, test::kFdStep);
      const Matrix fu = test::numeric_jacobian([&](const Vector& us) { return cp.f(x, us); }, u, test::kFdStep);
      EXPECT_TRUE(test::matrices_near(jac.fx, fx, test::kFdTolerance, test::kFdTolerance)) << "seed " << seed;
      EXPECT_TRUE(test::matrices_near(jac.fu, fu, test::kFdTolerance, test::kFdTolerance)) << "seed " << seed;
      EXPECT_MATRIX_NEAR(xdot, cp.f(x, u), 0.0);
    }
  }
}

TEST(CartPole, MatchesTheClosedFormEquationsOfTheReference) {
  // The reference README's explicit formulas, evaluated independently of the manipulator form.
  const CartPoleParameters p = CartPoleParameters::real_world();
  const CartPole cp(p);
  const double mc = p.cart_mass, mp = p.pole_mass, l = p.pole_length, g = p.gravity;
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Vector x = test::random_vector(4, -3.0, 3.0, seed);
    const double u = 2.0 * seed - 7.0;
    const double s = std::sin(x(2)), c = std::cos(x(2)), thd = x(3);
    Vector expected(4);
    expected << x(1), (u + mp * s * (l * thd * thd + g * c)) / (mc + mp * s * s), thd,
        (-u * c - mp * l * thd * thd * c * s - (mc + mp) * g * s) / (l * (mc + mp * s * s));
    EXPECT_MATRIX_NEAR(cp.f(x, Vector::Constant(1, u)), expected, 1e-13);
  }
}

TEST(CartPole, InputMatrixIsFuAndItsDerivativeMatchesCentralDifferences) {
  const CartPole cp;
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Vector x = test::random_vector(4, -3.0, 3.0, seed);
    const Vector u = test::random_vector(1, -5.0, 5.0, seed + 50);
    InputMatrix b;
    cp.input_matrix(x, u, b);
    DynamicsJacobians jac;
    Vector xdot(4);
    cp.evaluate(x, u, xdot, &jac);
    EXPECT_MATRIX_NEAR(b.b, jac.fu, 1e-15);
    const Matrix db = test::numeric_jacobian(
        [&](const Vector& xs) {
          DynamicsJacobians j;
          Vector f(4);
          cp.evaluate(xs, u, f, &j);
          return Vector(j.fu.col(0));
        },
        x, test::kFdStep);
    EXPECT_MATRIX_NEAR(b.d_dx[0], db, test::kFdTolerance);
    EXPECT_MATRIX_NEAR(b.d_du[0], Matrix::Zero(4, 1), 0.0);
  }
}

TEST(CartPole, PresetsAreThePapersAppendix) {
  EXPECT_DOUBLE_EQ(CartPoleParameters::simulator().pole_length, 1.0);
  EXPECT_DOUBLE_EQ(CartPoleParameters::real_world().pole_length, 1.3);  // "a 30% longer pole"
  EXPECT_DOUBLE_EQ(CartPoleParameters::real_world().cart_mass, 1.0);
  EXPECT_DOUBLE_EQ(CartPoleParameters::real_world().pole_mass, 1.0);
  const auto params = CartPole(CartPoleParameters::real_world()).parameters();
  ASSERT_EQ(params.size(), 4u);
  EXPECT_EQ(params[2].name, "pole_length");
  EXPECT_EQ(params[2].unit, "m");
  EXPECT_DOUBLE_EQ(params[2].value, 1.3);
}

TEST(CartPole, NamedStatesAndControlsFollowTheFixedConvention) {
  const CartPole cp;
  ASSERT_EQ(cp.state_dim(), 4);
  ASSERT_EQ(cp.control_dim(), 1);
  EXPECT_EQ(cp.name(), "cartpole");
  EXPECT_EQ(names_of(cp.states()), (std::vector<std::string>{"x", "x_dot", "theta", "theta_dot"}));
  EXPECT_EQ(cp.controls()[0].name, "force");
  EXPECT_EQ(cp.controls()[0].unit, "N");
}

TEST(CartPole, HangingAndUprightAreEquilibria) {
  const CartPole cp;
  EXPECT_MATRIX_NEAR(cp.f(Vector::Zero(4), Vector::Zero(1)), Vector::Zero(4), 0.0);
  Vector up(4);
  up << 0.0, 0.0, std::numbers::pi, 0.0;
  EXPECT_MATRIX_NEAR(cp.f(up, Vector::Zero(1)), Vector::Zero(4), 1e-14);
}

TEST(CartPole, RejectsNonPositiveParametersNamingThem) {
  try {
    CartPole bad(CartPoleParameters{1.0, 1.0, -0.5, 9.81});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pole_length"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CartPole(CartPoleParameters{0.0, 1.0, 1.0, 9.81}), std::invalid_argument);
  EXPECT_THROW(CartPole(CartPoleParameters{1.0, std::nan(""), 1.0, 9.81}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
