// PDDP's GP belief step: its Jacobians against central differences, and the propagated belief against
// a Monte Carlo estimate of x' = x + f(x, u) with x ~ N(mu, Sigma) and f drawn from the GP posterior.
// Any backend with exact moment matching serves (fitted_moment_matcher.hpp): fitted with FITC and SSGP
// on a known smooth system, the step from a point belief is the backend's own prediction; the compact
// backend is rejected with the reason.

#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpilqg/gp/compact.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/gp_belief_dynamics.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "test_support.hpp"

namespace gpilqg::gp {
namespace {

constexpr int kN = 2, kM = 1, kD = 3;

/// Two GPs on z = [x0, x1, u] -> dx, trained on a smooth nonlinear map. The noise std 0.01 keeps
/// K well conditioned: the variance term sf^2 - tr(Kinv Q) cancels, and with sn = 1e-3 central
/// differences of it lose ~1e-7 to round-off (eps |Kinv| / h).
GpBeliefDynamics make_dynamics() {
  const int N = 60;
  const Matrix Z = gpilqg::test::random_vector(N * kD, -1.5, 1.5, 1).reshaped(N, kD);
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

/// Central differences with steps h and h/2 combined by Richardson extrapolation, (4 D(h/2) - D(h)) / 3:
/// truncation error O(h^4) instead of the O(h^2) of D(h) alone, so h can be large enough that the
/// rounding of the model's evaluation, divided by h, stays small; that part grows by a factor of 3.
template <class F>
Matrix extrapolated_jacobian(const F& f, const Vector& at, double h) {
  return (4.0 * gpilqg::test::numeric_jacobian(f, at, 0.5 * h) - gpilqg::test::numeric_jacobian(f, at, h)) / 3.0;
}

/// dv'/dv and dv'/du at a fixed belief (mu, Sigma) and control against central differences with step h
/// (extrapolated, above).
void expect_jacobians_match_central_differences(const GpBeliefDynamics& model, double h, const std::string& label) {
  Matrix Sigma(2, 2);
  Sigma << 0.04, 0.01, 0.01, 0.09;
  const Vector v = belief(Vector(Eigen::Vector2d(0.3, -0.2)), Sigma);
  const Vector u = Vector::Constant(1, 0.4);
  Vector next(5);
  BeliefJacobians jac;
  model.propagate(v, u, next, &jac);
  auto step_v = [&](const Vector& vs) { Vector out(5); model.propagate(vs, u, out); return out; };
  auto step_u = [&](const Vector& us) { Vector out(5); model.propagate(v, us, out); return out; };
  EXPECT_TRUE(gpilqg::test::matrices_near(jac.dv, extrapolated_jacobian(step_v, v, h), 1e-7, 1e-6)) << label;
  EXPECT_TRUE(gpilqg::test::matrices_near(jac.du, extrapolated_jacobian(step_u, u, h), 1e-7, 1e-6)) << label;
}

TEST(GpBeliefDynamics, JacobiansMatchCentralDifferences) {
  expect_jacobians_match_central_differences(make_dynamics(), 1e-6, "exact");
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

// ------------------------------------------------------------------------------------------------
// Any backend with exact moment matching

/// N = 80 noisy transitions of a damped pendulum, x = [angle, rate], u = torque, dt = 0.05:
/// inputs z = [x; u] (N x 3) and increments x' - x (N x 2).
struct PendulumData {
  Matrix inputs, increments;
};

PendulumData pendulum_data() {
  const int N = 80;
  PendulumData d;
  d.inputs = gpilqg::test::random_vector(N * kD, -1.5, 1.5, 11).reshaped(N, kD);
  d.increments.resize(N, kN);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  for (int i = 0; i < N; ++i) {
    const double angle = d.inputs(i, 0), rate = d.inputs(i, 1), torque = d.inputs(i, 2);
    d.increments(i, 0) = 0.05 * rate + noise(rng);
    d.increments(i, 1) = 0.05 * (-9.81 * std::sin(angle) - 0.5 * rate + torque) + noise(rng);
  }
  return d;
}

gp::FitOptions quick_fit() {
  gp::FitOptions fit;
  fit.restarts = 0;
  fit.max_evaluations = 60;
  return fit;
}

/// Fits the belief dynamics with `backend`, and the same per-output fits again for the backend's own
/// prediction: from a point belief (Sigma = 0), mu' = mu + m(z) and Sigma' = diag(v(z)), z = [mu; u].
/// Then the Jacobians against central differences at a nonzero Sigma.
void expect_belief_step_is_the_prediction(const GpBackend& backend) {
  const PendulumData data = pendulum_data();
  const GpBeliefDynamics model = GpBeliefDynamics::fit(kN, kM, 0.05, data.inputs, data.increments, backend, quick_fit());
  std::vector<std::unique_ptr<FittedGp>> fits;
  for (int a = 0; a < kN; ++a) fits.push_back(backend.fit(TrainingSet{data.inputs, data.increments.col(a)}, quick_fit()).model);
  Prediction p;
  Vector next(5), mu_next;
  Matrix Sigma_next;
  for (unsigned trial = 0; trial < 3; ++trial) {
    const Vector mu = gpilqg::test::random_vector(kN, -1.0, 1.0, 40 + trial);
    const Vector u = gpilqg::test::random_vector(kM, -1.0, 1.0, 50 + trial);
    model.propagate(belief(mu, Matrix::Zero(kN, kN)), u, next);
    unpack_belief(next, kN, mu_next, Sigma_next);
    Vector z(kD);
    z << mu, u;
    for (int a = 0; a < kN; ++a) {
      fits[static_cast<std::size_t>(a)]->predict(z, p);
      EXPECT_NEAR(mu_next(a), mu(a) + p.mean, 1e-8) << backend.name() << ": mean " << a << ", trial " << trial;
      EXPECT_NEAR(Sigma_next(a, a), p.variance, 1e-8) << backend.name() << ": variance " << a << ", trial " << trial;
    }
    EXPECT_EQ(Sigma_next(0, 1), 0.0) << backend.name();
  }
  // Step 2e-3: the fitted noise is ~1e-3, so FITC's Kinv = Kuu^-1 - (Kuu + Kuf Lambda^-1 Kfu)^-1 is
  // large and V_a = sf^2 - tr(Kinv Q) carries 1e-12 to 1e-11 of rounding, depending on the machine;
  // divided by h that is the difference's error. Measured on FITC's rate-variance entry d Sigma'_11 /
  // d mu_1 = -9.399e-6: the plain central difference is off by 1.1e-7 at h = 1e-4, 5.6e-6 at 1e-6,
  // and by 1.5e-9 at 3e-3 to 1e-2, where the truncation error of the other entries (3e-7 at 1e-2)
  // is what the extrapolation removes.
  expect_jacobians_match_central_differences(model, 2e-3, std::string(backend.name()));
}

TEST(GpBeliefDynamics, FitcServesPddp) {
  FitcOptions options;
  options.inducing = 15;
  expect_belief_step_is_the_prediction(FitcBackend(options));
}

TEST(GpBeliefDynamics, SsgpServesPddp) {
  SsgpOptions options;
  options.frequencies = 15;
  expect_belief_step_is_the_prediction(SsgpBackend(options));
}

TEST(GpBeliefDynamics, FittingOnTwoThreadsGivesTheSameModel) {
  // The outputs fitted concurrently and the belief step shared out: the same summaries and the same
  // belief step with Jacobians, bit for bit, as one thread.
  const PendulumData data = pendulum_data();
  const ExactGpBackend backend;
  std::vector<FitSummary> one_summaries, two_summaries;
  const GpBeliefDynamics one =
      GpBeliefDynamics::fit(kN, kM, 0.05, data.inputs, data.increments, backend, quick_fit(), &one_summaries, 1);
  const GpBeliefDynamics two =
      GpBeliefDynamics::fit(kN, kM, 0.05, data.inputs, data.increments, backend, quick_fit(), &two_summaries, 2);
  EXPECT_EQ(one.threads(), 1);
  EXPECT_EQ(two.threads(), 2);
  ASSERT_EQ(one_summaries.size(), 2u);
  ASSERT_EQ(two_summaries.size(), 2u);
  for (std::size_t a = 0; a < 2; ++a) EXPECT_EQ(one_summaries[a].nlml, two_summaries[a].nlml) << "output " << a;
  const Vector v = belief(Vector::Constant(kN, 0.3), 0.01 * Matrix::Identity(kN, kN));
  const Vector u = Vector::Constant(kM, 0.2);
  Vector next_one(v.size()), next_two(v.size());
  BeliefJacobians j_one, j_two;
  one.propagate(v, u, next_one, &j_one);
  two.propagate(v, u, next_two, &j_two);
  EXPECT_EQ(next_one, next_two);
  EXPECT_EQ(j_one.dv, j_two.dv);
  EXPECT_EQ(j_one.du, j_two.du);
  EXPECT_THROW(GpBeliefDynamics::fit(kN, kM, 0.05, data.inputs, data.increments, backend, quick_fit(), nullptr, 0),
               std::invalid_argument);
}

TEST(GpBeliefDynamics, TheBackendsThatServeAreExactFitcAndSsgp) {
  EXPECT_EQ(moment_matching_backends(), (std::vector<std::string>{"exact", "fitc", "ssgp"}));
}

TEST(GpBeliefDynamics, CompactIsRejectedWithTheReason) {
  const PendulumData data = pendulum_data();
  const auto expect_reason = [](const auto& f) {
    try {
      f();
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      for (const char* fragment : {"backend 'compact' cannot serve PDDP", "Wendland kernel has no closed-form expectation",
                                   "the backends that can are exact, fitc, ssgp"})
        EXPECT_NE(what.find(fragment), std::string::npos) << what;
    }
  };
  const CompactBackend compact;
  expect_reason([&] { GpBeliefDynamics::fit(kN, kM, 0.05, data.inputs, data.increments, compact, quick_fit()); });
  gp::FitOptions as_given = quick_fit();
  as_given.optimise = false;
  const auto fitted = compact.fit(TrainingSet{data.inputs, data.increments.col(0)}, as_given).model;
  expect_reason([&] { moment_matcher_for({fitted.get()}); });
}

}  // namespace
}  // namespace gpilqg::gp
