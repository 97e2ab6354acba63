// PDDP's GP belief step: its Jacobians against central differences, and the propagated belief against
// a Monte Carlo estimate of x' = x + f(x, u) with x ~ N(mu, Sigma) and f drawn from the GP posterior.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "gpilqg/gp/gp_belief_dynamics.hpp"
#include "test_support.hpp"

namespace gpilqg::gp {
namespace {

constexpr int kN = 2, kM = 1, kD = 3;

/// Two GPs on z = [x0, x1, u] -> dx, trained on a smooth nonlinear map. The noise std 0.01 keeps
/// K well conditioned: the variance term sf^2 - tr(Kinv Q) cancels, and with sn = 1e-3 central
/// differences of it lose ~1e-7 to round-off (eps |Kinv| / h).
GpBeliefDynamics make_dynamics() {
  const int N = 60;
  const Matrix Z = test::random_vector(N * kD, -1.5, 1.5, 1).reshaped(N, kD);
  Matrix dX(N, kN);
  for (int i = 0; i < N; ++i) {
    dX(i, 0) = 0.1 * Z(i, 1) + 0.05 * std::sin(2.0 * Z(i, 0));
    dX(i, 1) = -0.2 * std::sin(Z(i, 0)) + 0.1 * Z(i, 2) - 0.05 * Z(i, 1);
  }
  Vector h0(kD + 2), h1(kD + 2);
  h0 << std::log(0.9), std::log(1.2), std::log(2.0), std::log(0.1), std::log(1e-2);
  h1 << std::log(1.1), std::log(1.5), std::log(1.3), std::log(0.2), std::log(1e-2);
  return GpBeliefDynamics::condition(kN, kM, 0.05, Z, dX, {h0, h1});
}

Vector belief(const Vector& mu, const Matrix& Sigma) {
  Vector v(belief_dim(static_cast<int>(mu.size())));
  pack_belief(mu, Sigma, v);
  return v;
}

TEST(GpBeliefDynamics, JacobiansMatchCentralDifferences) {
  const GpBeliefDynamics model = make_dynamics();
  Matrix Sigma(2, 2);
  Sigma << 0.04, 0.01, 0.01, 0.09;
  const Vector v = belief(Vector(Eigen::Vector2d(0.3, -0.2)), Sigma);
  const Vector u = Vector::Constant(1, 0.4);
  Vector next(5);
  BeliefJacobians jac;
  model.propagate(v, u, next, &jac);
  auto step_v = [&](const Vector& vs) { Vector out(5); model.propagate(vs, u, out); return out; };
  auto step_u = [&](const Vector& us) { Vector out(5); model.propagate(v, us, out); return out; };
  EXPECT_TRUE(test::matrices_near(jac.dv, test::numeric_jacobian(step_v, v, 1e-6), 1e-7, 1e-6));
  EXPECT_TRUE(test::matrices_near(jac.du, test::numeric_jacobian(step_u, u, 1e-6), 1e-7, 1e-6));
}

TEST(GpBeliefDynamics, PropagatedBeliefMatchesMonteCarlo) {
  const GpBeliefDynamics model = make_dynamics();
  const Vector mu(Eigen::Vector2d(0.2, 0.1));
  Matrix Sigma(2, 2);
  Sigma << 0.05, -0.01, -0.01, 0.03;
  const Vector u = Vector::Constant(1, -0.3);
  Vector next(5), mu_next;
  Matrix Sigma_next;
  model.propagate(belief(mu, Sigma), u, next);
  unpack_belief(next, 2, mu_next, Sigma_next);

  // Monte Carlo with a point belief per sample: x ~ N(mu, Sigma); the GP's own predictive moments at
  // (x, u) come from the same model with Sigma = 0. Then E[x'] = E[x + m(x)] and
  // Cov[x'] = Cov[x + m(x)] + E[diag var(x)].
  const Eigen::LLT<Matrix> chol(Sigma);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const int samples = 40000;
  Vector sum = Vector::Zero(2);
  Matrix outer = Matrix::Zero(2, 2), mean_var = Matrix::Zero(2, 2);
  Vector point(5), out(5), m;
  Matrix var;
  for (int k = 0; k < samples; ++k) {
    const Vector x = mu + chol.matrixL() * Vector(Eigen::Vector2d(normal(rng), normal(rng)));
    model.propagate(belief(x, Matrix::Zero(2, 2)), u, out);
    unpack_belief(out, 2, m, var);  // m = x + mean increment, var = diag latent variances
    sum += m;
    outer += m * m.transpose();
    mean_var += var;
  }
  const Vector mc_mean = sum / samples;
  const Matrix mc_cov = outer / samples - mc_mean * mc_mean.transpose() + mean_var / samples;
  for (int a = 0; a < 2; ++a) {
    const double se_mean = std::sqrt(mc_cov(a, a) / samples);
    EXPECT_NEAR(mu_next(a), mc_mean(a), 4.0 * se_mean) << "mean " << a;
    for (int b = 0; b < 2; ++b) {
      const double se_cov = std::sqrt((mc_cov(a, a) * mc_cov(b, b) + mc_cov(a, b) * mc_cov(a, b)) / samples);
      EXPECT_NEAR(Sigma_next(a, b), mc_cov(a, b), 4.0 * se_cov) << "covariance " << a << "," << b;
    }
  }
}

TEST(GpBeliefDynamics, RejectsMismatchedShapes) {
  const Matrix Z = Matrix::Random(10, 3), dX = Matrix::Random(10, 2);
  Vector h = Vector::Zero(5);
  EXPECT_THROW(GpBeliefDynamics::condition(2, 1, 0.05, Z, dX, {h}), std::invalid_argument);
  EXPECT_THROW(GpBeliefDynamics::condition(2, 2, 0.05, Z, dX, {h, h}), std::invalid_argument);
  const GpBeliefDynamics model = make_dynamics();
  Vector out(5);
  EXPECT_THROW(model.propagate(Vector::Zero(4), Vector::Zero(1), out), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg::gp
