// Rollouts: the deterministic path equals repeated steps; sampled noise has the covariance
// dt F F' that the paper's discrete model implies (Monte Carlo); divergence is reported, not hidden.

#include <cmath>

#include <gtest/gtest.h>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

TEST(Rollout, DeterministicRolloutRepeatsTheMeanStep) {
  IntegratedStepModel model(make_system("cartpole"), Integrator::RK4, 0.05);
  const Matrix u = test::random_vector(30, -2, 2, 1).transpose();
  const Vector x0 = Vector::Zero(4);
  const RolloutResult r = rollout(model, x0, u);
  ASSERT_TRUE(r.finite);
  EXPECT_EQ(r.steps_completed, 30);
  Vector x = x0;
  for (int t = 0; t < 30; ++t) x = model.next(x, u.col(t));
  EXPECT_MATRIX_NEAR(r.trajectory.x.col(30), x, 0.0);
  EXPECT_MATRIX_NEAR(r.trajectory.u, u, 0.0);
}

TEST(Rollout, SampledOneStepCovarianceIsDtFFTranspose) {
  // x' - phi(x, u) = sqrt(dt) F xi, so its covariance is dt F F'. With N = 20000 samples the
  // standard error of a covariance entry S_ij is about sqrt((S_ii S_jj + S_ij^2) / N); we allow 5 of them.
  ActuatorNoise noise;
  noise.additive_std = Vector::Constant(1, 0.5);
  noise.multiplicative_std = Vector::Constant(1, 0.3);
  noise.state_std = Vector::Constant(4, 0.02);
  IntegratedStepModel model(make_system("cartpole", Preset::RealWorld, {}, noise), Integrator::RK4, 0.05);
  Vector x0(4);
  x0 << 0.1, 0.2, 1.0, -0.5;
  const Matrix u = Matrix::Constant(1, 1, 3.0);
  DiffusionColumns F;
  model.noise(x0, u.col(0), F, false);
  const Matrix expected = model.dt() * F.columns * F.columns.transpose();
  const Vector mean = model.next(x0, u.col(0));

  std::mt19937_64 rng(42);
  const int N = 20000;
  Matrix S = Matrix::Zero(4, 4);
  for (int k = 0; k < N; ++k) {
    const Vector d = rollout(model, x0, u, RolloutNoise::Process, &rng).trajectory.x.col(1) - mean;
    S += d * d.transpose();
  }
  S /= N;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double se = std::sqrt((expected(i, i) * expected(j, j) + expected(i, j) * expected(i, j)) / N);
      EXPECT_NEAR(S(i, j), expected(i, j), 5.0 * se + 1e-15) << i << "," << j;
    }
}

TEST(Rollout, ADivergingRolloutStopsAndSaysSo) {
  // x' = x^2: from 10 it overflows to infinity within a few steps.
  FiniteDifferenceStepModel exploding(1, 1, 0.1, [](const Vector& x, const Vector&, Vector& next) {
    next = x.array().square();
  });
  const RolloutResult r = rollout(exploding, Vector::Constant(1, 10.0), Matrix::Zero(1, 20));
  EXPECT_FALSE(r.finite);
  EXPECT_LT(r.steps_completed, 20);
  EXPECT_TRUE(r.trajectory.x.allFinite());
}

TEST(Rollout, RejectsMismatchedSizesAndMissingGenerator) {
  IntegratedStepModel model(make_system("cartpole"), Integrator::Euler, 0.05);
  EXPECT_THROW(rollout(model, Vector::Zero(3), Matrix::Zero(1, 5)), std::invalid_argument);
  EXPECT_THROW(rollout(model, Vector::Zero(4), Matrix::Zero(2, 5)), std::invalid_argument);
  EXPECT_THROW(rollout(model, Vector::Zero(4), Matrix::Zero(1, 5), RolloutNoise::Process), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
