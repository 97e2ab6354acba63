// Multiplicative and additive noise F(x, u): its columns, and the derivatives of every column against
// central differences, for both systems and for the default (finite-difference) input matrix.

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

ActuatorNoise full_noise(int n, int m) {
  ActuatorNoise noise;
  noise.additive_std = Vector::LinSpaced(m, 0.1, 0.2);
  noise.multiplicative_std = Vector::LinSpaced(m, 0.3, 0.5);
  noise.state_std = Vector::Zero(n);
  noise.state_std(n - 1) = 0.05;  // one nonzero entry: one column
  return noise;
}

Vector column_of(const Dynamics& d, const Vector& x, const Vector& u, int column) {
  DiffusionColumns out;
  d.noise(x, u, out, false);
  return out.columns.col(column);
}

class NoiseColumnTest : public ::testing::TestWithParam<std::string> {};

TEST_P(NoiseColumnTest, ColumnsAreTheActuatorDirectionsScaledByTheirStandardDeviations) {
  const auto signature = system_signature(GetParam());
  const int n = static_cast<int>(signature.states.size()), m = static_cast<int>(signature.controls.size());
  auto system = make_system(GetParam(), Preset::Simulator, {}, full_noise(n, m));
  ASSERT_EQ(system->noise_dim(), 2 * m + 1);

  const Vector x = test::random_vector(n, -1.0, 1.0, 1), u = test::random_vector(m, 0.5, 3.0, 2);
  DiffusionColumns F;
  system->noise(x, u, F, true);
  DynamicsJacobians jac;
  Vector xdot(n);
  system->evaluate(x, u, xdot, &jac);
  const auto& noise = system->noise_model();
  for (int j = 0; j < m; ++j) {
    EXPECT_MATRIX_NEAR(F.columns.col(j), Vector(noise.additive_std(j) * jac.fu.col(j)), 1e-15);
    EXPECT_MATRIX_NEAR(F.columns.col(m + j),
                       Vector(noise.multiplicative_std(j) * u(j) * jac.fu.col(j)), 1e-15);
  }
  Vector state_column = Vector::Zero(n);
  state_column(n - 1) = 0.05;
  EXPECT_MATRIX_NEAR(F.columns.col(2 * m), state_column, 0.0);
}

TEST_P(NoiseColumnTest, ColumnDerivativesMatchCentralDifferences) {
  const auto signature = system_signature(GetParam());
  const int n = static_cast<int>(signature.states.size()), m = static_cast<int>(signature.controls.size());
  auto system = make_system(GetParam(), Preset::RealWorld, {}, full_noise(n, m));
  for (unsigned seed = 0; seed < 5; ++seed) {
    const Vector x = test::random_vector(n, -2.0, 2.0, seed), u = test::random_vector(m, -3.0, 3.0, seed + 9);
    DiffusionColumns F;
    system->noise(x, u, F, true);
    for (int i = 0; i < F.count(); ++i) {
      const Matrix dx = test::numeric_jacobian([&](const Vector& xs) { return column_of(*system, xs, u, i); }, x, 1e-6);
      const Matrix du = test::numeric_jacobian([&](const Vector& us) { return column_of(*system, x, us, i); }, u, 1e-6);
      EXPECT_TRUE(test::matrices_near(F.d_dx[static_cast<std::size_t>(i)], dx, 1e-8, 1e-7)) << "column " << i;
      EXPECT_TRUE(test::matrices_near(F.d_du[static_cast<std::size_t>(i)], du, 1e-8, 1e-7)) << "column " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BothSystems, NoiseColumnTest, ::testing::Values("cartpole", "quadrotor"));

TEST(Noise, DefaultFiniteDifferenceInputMatrixAgreesWithTheAnalyticOne) {
  auto analytic = std::make_shared<CartPole>();
  FiniteDifferenceDynamics black_box(
      "bb", analytic->states(), analytic->controls(), analytic->parameters(),
      [analytic](const Vector& x, const Vector& u, Vector& xdot) { analytic->evaluate(x, u, xdot); });
  const Vector x = test::random_vector(4, -2.0, 2.0, 4), u = Vector::Constant(1, 1.1);
  InputMatrix exact, numeric;
  analytic->input_matrix(x, u, exact);
  black_box.input_matrix(x, u, numeric);
  EXPECT_TRUE(test::matrices_near(numeric.b, exact.b, 1e-8, 1e-8));
  // Second derivatives from differences of first-difference Jacobians: error ~ eps^(1/3) / h.
  EXPECT_TRUE(test::matrices_near(numeric.d_dx[0], exact.d_dx[0], 1e-4, 1e-4));
  EXPECT_TRUE(test::matrices_near(numeric.d_du[0], exact.d_du[0], 1e-4));
}

TEST(Noise, StepModelPassesTheDynamicsNoiseThrough) {
  auto system = std::make_shared<CartPole>();
  ActuatorNoise noise;
  noise.multiplicative_std = Vector::Constant(1, 0.2);
  system->set_noise_model(noise);
  IntegratedStepModel model(system, Integrator::RK4, 0.05);
  EXPECT_EQ(model.noise_dim(), 1);
  EXPECT_EQ(model.uncertainty_dim(), 0);
  const Vector x = Vector::Zero(4), u = Vector::Constant(1, 2.0);
  DiffusionColumns a, b;
  model.noise(x, u, a, true);
  system->noise(x, u, b, true);
  EXPECT_MATRIX_NEAR(a.columns, b.columns, 0.0);
  // Without noise there are no columns at all.
  auto quiet = std::make_shared<CartPole>();
  IntegratedStepModel deterministic(quiet, Integrator::Euler, 0.05);
  DiffusionColumns none;
  deterministic.noise(x, u, none, true);
  EXPECT_EQ(none.count(), 0);
}

TEST(Noise, RejectsWrongSizesAndNegativeDeviationsNamingTheField) {
  CartPole system;
  ActuatorNoise wrong_size;
  wrong_size.additive_std = Vector::Ones(3);
  try {
    system.set_noise_model(wrong_size);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("additive_std"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected 1"), std::string::npos) << e.what();
  }
  ActuatorNoise negative;
  negative.state_std = Vector::Constant(4, -0.1);
  EXPECT_THROW(system.set_noise_model(negative), std::invalid_argument);
  ActuatorNoise not_finite;
  not_finite.multiplicative_std = Vector::Constant(1, std::nan(""));
  EXPECT_THROW(system.set_noise_model(not_finite), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
