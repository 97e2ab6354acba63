// The example plugin's acrobot (examples/acrobot_plugin): analytic Jacobians fx, fu, the input matrix
// and the generalised-force map's dW/dx against central differences; W against the torque's own
// direction; energy conservation; the presets and parameter validation.

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "acrobot.hpp"
#include "gpilqg/core/integrator.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

using acrobot::Acrobot;
using acrobot::AcrobotParameters;

const AcrobotParameters kParameterSets[] = {AcrobotParameters::simulator(), AcrobotParameters::real_world(),
                                           AcrobotParameters{0.6, 1.7, 0.8, 1.4, 9.81}};

TEST(Acrobot, AnalyticJacobiansMatchCentralDifferencesAtRandomPoints) {
  for (const auto& params : kParameterSets) {
    const Acrobot system(params);
    for (unsigned seed = 0; seed < 25; ++seed) {
      const Vector x = test::random_vector(4, -4.0, 4.0, seed);
      const Vector u = test::random_vector(1, -10.0, 10.0, 1000 + seed);
      DynamicsJacobians jac;
      Vector xdot(4);
      system.evaluate(x, u, xdot, &jac);
      EXPECT_TRUE(test::matrices_near(xdot, system.f(x, u), 0.0)) << "seed " << seed;
      const Matrix fx = test::numeric_jacobian([&](const Vector& xs) { return system.f(xs, u); }, x, test::kFdStep);
      const Matrix fu = test::numeric_jacobian([&](const Vector& us) { return system.f(x, us); }, u, test::kFdStep);
      EXPECT_TRUE(test::matrices_near(jac.fx, fx, test::kFdTolerance, test::kFdTolerance)) << "seed " << seed;
      EXPECT_TRUE(test::matrices_near(jac.fu, fu, test::kFdTolerance, test::kFdTolerance)) << "seed " << seed;
    }
  }
}

TEST(Acrobot, InputMatrixIsFuWithCentralDifferenceDerivatives) {
  for (const auto& params : kParameterSets) {
    const Acrobot system(params);
    for (unsigned seed = 0; seed < 10; ++seed) {
      const Vector x = test::random_vector(4, -4.0, 4.0, 50 + seed);
      const Vector u = test::random_vector(1, -10.0, 10.0, 1050 + seed);
      InputMatrix b;
      system.input_matrix(x, u, b);
      DynamicsJacobians jac;
      Vector xdot(4);
      system.evaluate(x, u, xdot, &jac);
      EXPECT_TRUE(test::matrices_near(b.b, jac.fu, 1e-12, 1e-12)) << "seed " << seed;
      const auto column = [&](const Vector& xs) {
        InputMatrix at;
        system.input_matrix(xs, u, at);
        return Vector(at.b.col(0));
      };
      EXPECT_TRUE(test::matrices_near(b.d_dx[0], test::numeric_jacobian(column, x, test::kFdStep), test::kFdTolerance,
                                      test::kFdTolerance))
          << "seed " << seed;
      EXPECT_TRUE(test::matrices_near(b.d_du[0], Matrix::Zero(4, 1), 0.0));
    }
  }
}

TEST(Acrobot, GeneralisedForceMapDerivativesMatchCentralDifferences) {
  for (const auto& params : kParameterSets) {
    const Acrobot system(params);
    for (unsigned seed = 0; seed < 10; ++seed) {
      const Vector x = test::random_vector(4, -4.0, 4.0, 100 + seed);
      Matrix W;
      std::vector<Matrix> dW;
      system.generalised_force_map(x, W, &dW);
      ASSERT_EQ(W.rows(), 4);
      ASSERT_EQ(W.cols(), 2);
      ASSERT_EQ(dW.size(), 4u);
      for (int k = 0; k < 2; ++k) {
        const auto column = [&](const Vector& xs) {
          Matrix at;
          system.generalised_force_map(xs, at, nullptr);
          return Vector(at.col(k));
        };
        const Matrix numeric = test::numeric_jacobian(column, x, test::kFdStep);  // 4 x 4: d W(:, k) / dx
        for (int j = 0; j < 4; ++j)
          EXPECT_TRUE(test::matrices_near(dW[static_cast<std::size_t>(j)].col(k), numeric.col(j), test::kFdTolerance,
                                          test::kFdTolerance))
              << "seed " << seed << ", column " << k << ", x_" << j;
      }
    }
  }
}

TEST(Acrobot, ElbowTorqueEntersThroughTheSecondColumnOfW) {
  // The motor is a generalised force on theta2, so xdot(x, u) = xdot(x, 0) + W(x) [0; u].
  const Acrobot system(AcrobotParameters::real_world());
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Vector x = test::random_vector(4, -3.0, 3.0, 200 + seed);
    const Vector u = test::random_vector(1, -5.0, 5.0, 300 + seed);
    Matrix W;
    system.generalised_force_map(x, W, nullptr);
    const Vector expected = system.f(x, Vector::Zero(1)) + W.col(1) * u(0);
    EXPECT_TRUE(test::matrices_near(system.f(x, u), expected, 1e-12, 1e-12)) << "seed " << seed;
  }
}

TEST(Acrobot, EnergyIsConservedWithoutTorque) {
  const auto system = std::make_shared<const Acrobot>(AcrobotParameters::real_world());
  const IntegratedStepModel model(system, Integrator::RK4, 1e-3);
  Vector x(4);
  x << 1.2, -0.7, 0.5, 2.0;
  const double e0 = system->energy(x);
  const Vector u = Vector::Zero(1);
  Vector next(4);
  for (int k = 0; k < 3000; ++k) {
    model.step(x, u, next);
    x = next;
  }
  EXPECT_GT(e0, 1.0);
  EXPECT_NEAR(system->energy(x), e0, 1e-7 * e0);
  EXPECT_DOUBLE_EQ(system->energy(Vector::Zero(4)), 0.0);
}

TEST(Acrobot, PresetsAndValidation) {
  EXPECT_DOUBLE_EQ(AcrobotParameters::real_world().link2_mass, 1.3);
  EXPECT_DOUBLE_EQ(AcrobotParameters::simulator().link2_mass, 1.0);
  const Acrobot system;
  EXPECT_EQ(system.name(), "acrobot");
  ASSERT_EQ(system.states().size(), 4u);
  EXPECT_EQ(system.states()[3].name, "theta2_dot");
  EXPECT_EQ(system.controls()[0].name, "tau");
  EXPECT_EQ(system.parameters().size(), 5u);
  AcrobotParameters bad;
  bad.link2_length = 0.0;
  try {
    Acrobot{bad};
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("link2_length"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gpilqg
