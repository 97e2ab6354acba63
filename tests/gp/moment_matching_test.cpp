/// Exact moment matching of SE-ARD GPs (moment_matching.hpp) against independent references:
///  1. Sigma = 0: the plain GP posterior mean and latent variance, computed here from the kernel;
///  2. Monte Carlo with 1e5 input samples: M, S and C within 4 standard errors;
///  3. every derivative against central differences (one Sigma entry at a time, and symmetric pairs);
///  4. size and value validation.
/// The GPs are conditioned here with Eigen's LLT, independently of the library's helper.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "gpilqg/gp/moment_matching.hpp"
#include "moment_matching_checks.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::test {
namespace {

using ::gpilqg::test::matrices_near;
using ::gpilqg::test::numeric_jacobian;

double se_ard(const VectorCRef& x, const VectorCRef& y, const Vector& log_l, double log_sf) {
  const double r2 = ((x - y).array() / log_l.array().exp()).square().sum();
  return std::exp(2.0 * log_sf - 0.5 * r2);
}

/// E independent GPs on N random inputs in [-spread, spread]^D with smooth targets; beta and Kinv
/// from LLT.
struct TestGp {
  Matrix inputs;
  std::vector<SeArdOutput> outputs;

  Vector kernel_column(int a, const VectorCRef& z) const {
    Vector k(inputs.rows());
    for (Eigen::Index i = 0; i < inputs.rows(); ++i)
      k(i) = se_ard(inputs.row(i).transpose(), z, outputs[a].log_lengthscales, outputs[a].log_signal_std);
    return k;
  }
  double posterior_mean(int a, const VectorCRef& z) const { return outputs[a].beta.dot(kernel_column(a, z)); }
  double posterior_variance(int a, const VectorCRef& z) const {
    const Vector k = kernel_column(a, z);
    return std::exp(2.0 * outputs[a].log_signal_std) - k.dot(outputs[a].Kinv * k);
  }
  SeArdMomentMatcher matcher() const { return SeArdMomentMatcher(inputs, outputs); }
};

TestGp make_gp(int n, int d, int e, unsigned seed, double spread = 1.0) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> uniform(-spread, spread);
  std::uniform_real_distribution<double> log_l(std::log(0.5), std::log(1.5));
  std::uniform_real_distribution<double> log_sf(std::log(0.5), std::log(1.5));
  std::normal_distribution<double> noise(0.0, 0.05);
  TestGp gp;
  gp.inputs.resize(n, d);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < d; ++j) gp.inputs(i, j) = uniform(gen);
  const double sn2 = 0.1 * 0.1;
  for (int a = 0; a < e; ++a) {
    SeArdOutput o;
    o.log_lengthscales.resize(d);
    for (int j = 0; j < d; ++j) o.log_lengthscales(j) = log_l(gen);
    o.log_signal_std = log_sf(gen);
    Vector y(n);
    for (int i = 0; i < n; ++i) {
      const auto x = gp.inputs.row(i);
      y(i) = std::sin(2.0 * x(0) + a) + 0.5 * x(d - 1) * x(0) + 0.3 * (a + 1) * x(d / 2) + noise(gen);
    }
    Matrix k(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        k(i, j) = se_ard(gp.inputs.row(i).transpose(), gp.inputs.row(j).transpose(), o.log_lengthscales,
                         o.log_signal_std);
    k.diagonal().array() += sn2;
    const Eigen::LLT<Matrix> llt(k);
    EXPECT_EQ(llt.info(), Eigen::Success);
    o.beta = llt.solve(y);
    o.Kinv = llt.solve(Matrix::Identity(n, n));
    gp.outputs.push_back(o);
  }
  return gp;
}

// ------------------------------------------------------------------------------------------------
// 1. Deterministic input

TEST(MomentMatching, DeterministicInputIsTheGpPosterior) {
  const TestGp gp = make_gp(25, 4, 3, 11);
  const SeArdMomentMatcher matcher = gp.matcher();
  MomentMatch m;
  const Matrix zero = Matrix::Zero(4, 4);
  for (unsigned trial = 0; trial < 4; ++trial) {
    // one test point far from the data, the rest inside it; one exactly at a training input
    Vector mu = ::gpilqg::test::random_vector(4, -1.0, 1.0, 100 + trial);
    if (trial == 2) mu = gp.inputs.row(5).transpose();
    if (trial == 3) mu *= 3.0;
    matcher.propagate(mu, zero, m, MomentDerivatives::All);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(m.mean(a), gp.posterior_mean(a, mu), 1e-12) << "output " << a << ", trial " << trial;
      EXPECT_NEAR(m.covariance(a, a), gp.posterior_variance(a, mu), 1e-12) << "output " << a;
      for (int b = 0; b < 3; ++b)
        if (b != a) {
          EXPECT_NEAR(m.covariance(a, b), 0.0, 1e-12) << a << ", " << b;
        }
    }
    EXPECT_TRUE(m.cross_covariance.isZero(0.0));
    // dM/dmu at Sigma = 0 is the GP mean gradient sum_i beta_i k_i W (x_i - mu).
    for (int a = 0; a < 3; ++a) {
      const Vector k = gp.kernel_column(a, mu);
      const Vector w = (-2.0 * gp.outputs[a].log_lengthscales.array()).exp().matrix();
      const Vector grad = w.asDiagonal() *
                          ((gp.inputs.rowwise() - mu.transpose()).transpose() * gp.outputs[a].beta.cwiseProduct(k));
      EXPECT_TRUE(matrices_near(m.dmean_dmu.row(a).transpose(), grad, 1e-12));
    }
  }
}

// ------------------------------------------------------------------------------------------------
// 2. Monte Carlo

/// The Monte Carlo check with the GP posterior computed here from the kernel as the integrand.
MonteCarloCheck check_gp_against_monte_carlo(const TestGp& gp, const Vector& mu, const Matrix& sigma, int samples,
                                             const std::string& label) {
  const auto posterior = [&gp](const Vector& z, Vector& mean, Vector& variance) {
    for (int a = 0; a < static_cast<int>(gp.outputs.size()); ++a) {
      mean(a) = gp.posterior_mean(a, z);
      variance(a) = gp.posterior_variance(a, z);
    }
  };
  return test::check_against_monte_carlo(gp.matcher(), posterior, mu, sigma, samples, label);
}

TEST(MomentMatching, AgreesWithMonteCarlo) {
  const TestGp gp = make_gp(20, 3, 2, 5);
  Vector mu(3);
  mu << 0.2, -0.3, 0.1;
  const Matrix sigma = make_sigma(3, 0.45, 7);
  check_gp_against_monte_carlo(gp, mu, sigma, 100000, "full Sigma");
}

TEST(MomentMatching, AgreesWithMonteCarloWithADeterministicInput) {
  const TestGp gp = make_gp(20, 3, 2, 5);
  Vector mu(3);
  mu << -0.1, 0.4, 0.3;
  const Matrix sigma = make_sigma(3, 0.5, 8, /*zero_index=*/2);
  check_gp_against_monte_carlo(gp, mu, sigma, 100000, "zero row 2");
  MomentMatch m;
  gp.matcher().propagate(mu, sigma, m);
  EXPECT_TRUE(m.cross_covariance.row(2).isZero(1e-15));
}

// ------------------------------------------------------------------------------------------------
// 3. Derivatives against central differences

void check_gp_derivatives(const TestGp& gp, const Vector& mu, const Matrix& sigma, const std::string& label) {
  test::check_derivatives(gp.matcher(), mu, sigma, label);
}

TEST(MomentMatching, DerivativesMatchCentralDifferences) {
  const TestGp gp = make_gp(15, 4, 3, 21);
  Vector mu(4);
  mu << 0.3, -0.2, 0.5, 0.1;
  check_gp_derivatives(gp, mu, make_sigma(4, 0.4, 3), "full Sigma");
}

TEST(MomentMatching, DerivativesMatchCentralDifferencesWithADeterministicInput) {
  const TestGp gp = make_gp(15, 4, 3, 22);
  Vector mu(4);
  mu << -0.4, 0.1, 0.2, 0.6;
  check_gp_derivatives(gp, mu, make_sigma(4, 0.4, 4, /*zero_index=*/3), "zero row 3");
}

TEST(MomentMatching, DerivativesMatchCentralDifferencesAtSigmaZero) {
  const TestGp gp = make_gp(12, 3, 2, 23);
  Vector mu(3);
  mu << 0.1, 0.2, -0.3;
  check_gp_derivatives(gp, mu, Matrix::Zero(3, 3), "Sigma = 0");
}

TEST(MomentMatching, DerivativesMatchCentralDifferencesOneInputOneOutput) {
  const TestGp gp = make_gp(10, 1, 1, 24);
  check_gp_derivatives(gp, Vector::Constant(1, 0.2), Matrix::Constant(1, 1, 0.3), "D = E = 1");
}

TEST(MomentMatching, LargeTrainingSetsGoThroughTheTiledProducts) {
  // N > 128: every N-sized product is split into 128-tiles (moment_matching_internal.hpp).
  // Spread out so that K + sn^2 I stays well conditioned: with 300 points in [-1, 1]^3 the cancellation
  // in sf^2 - tr(Kinv Q) leaves ~1e-12 of rounding in S, i.e. ~1e-7 in a central difference with
  // h = 1e-5 (checked: the difference then grows again for smaller h), which is noise, not a bug.
  const TestGp gp = make_gp(300, 3, 2, 25, /*spread=*/3.0);
  Vector mu(3);
  mu << 0.2, 0.1, -0.1;
  check_gp_derivatives(gp, mu, make_sigma(3, 0.3, 6, /*zero_index=*/2), "N = 300");
  MomentMatch m;
  gp.matcher().propagate(mu, Matrix::Zero(3, 3), m);
  for (int a = 0; a < 2; ++a) {
    EXPECT_NEAR(m.mean(a), gp.posterior_mean(a, mu), 1e-10);
    EXPECT_NEAR(m.covariance(a, a), gp.posterior_variance(a, mu), 1e-10);
  }
}

// ------------------------------------------------------------------------------------------------
// Ill-conditioned GPs: nearly noise-free data (regression test for the cancellation in S)

/// E = 2 GPs on N = 300 inputs in [-2, 2] x [-2, 2] x [-1, 1] (angle, rate, torque) with smooth
/// pendulum-like targets plus N(0, (1e-3 std y)^2), sn = 1e-3 std(y), sf = std(y), length-scales ~1.
/// K + sn^2 I then has a condition number ~1e9 and |beta| reaches ~1e5 / sf: the old evaluation
/// beta' Q beta - M_a M_b lost everything (off-diagonals ~1e-4 at Sigma = 0, negative variances).
/// Keeps the Cholesky factors for the reference latent variance sf^2 - ||L^-1 k||^2.
struct IllConditionedGp {
  TestGp gp;
  std::vector<Matrix> factors;  // L_a, K_a + sn_a^2 I = L_a L_a'
};

IllConditionedGp make_ill_conditioned_gp() {
  const int n = 300;
  const int d = 3;
  std::mt19937 gen(77);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  IllConditionedGp out;
  TestGp& gp = out.gp;
  gp.inputs.resize(n, d);
  for (int i = 0; i < n; ++i) gp.inputs.row(i) << unit(gen), unit(gen), unit(gen);
  for (int a = 0; a < 2; ++a) {
    Vector y(n);
    for (int i = 0; i < n; ++i) {
      const double theta = gp.inputs(i, 0), rate = gp.inputs(i, 1), torque = gp.inputs(i, 2);
      y(i) = a == 0 ? 0.1 * rate - 0.05 * std::sin(theta)
                    : -0.9 * std::sin(theta) - 0.1 * rate + 0.5 * torque;  // one damped-pendulum step
    }
    const double sd = std::sqrt((y.array() - y.mean()).square().sum() / (n - 1.0));
    for (int i = 0; i < n; ++i) y(i) += 1e-3 * sd * normal(gen);
    SeArdOutput o;
    o.log_lengthscales = Vector::Constant(d, 0.0);
    o.log_lengthscales(a) = std::log(0.9);
    o.log_signal_std = std::log(sd);
    Matrix k(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        k(i, j) = se_ard(gp.inputs.row(i).transpose(), gp.inputs.row(j).transpose(), o.log_lengthscales,
                         o.log_signal_std);
    k.diagonal().array() += (1e-3 * sd) * (1e-3 * sd);
    const Eigen::LLT<Matrix> llt(k);
    EXPECT_EQ(llt.info(), Eigen::Success);
    o.beta = llt.solve(y);
    o.Kinv = llt.solve(Matrix::Identity(n, n));
    out.factors.push_back(llt.matrixL());
    gp.outputs.push_back(o);
  }
  return out;
}

TEST(MomentMatching, NearlyNoiseFreeGpsGiveAnExactlyDiagonalCovarianceAtSigmaZero) {
  const IllConditionedGp ill = make_ill_conditioned_gp();
  const TestGp& gp = ill.gp;
  const SeArdMomentMatcher matcher = gp.matcher();
  std::printf("  max |beta| %.2e, %.2e; max |Kinv| %.2e, %.2e\n", gp.outputs[0].beta.cwiseAbs().maxCoeff(),
              gp.outputs[1].beta.cwiseAbs().maxCoeff(), gp.outputs[0].Kinv.cwiseAbs().maxCoeff(),
              gp.outputs[1].Kinv.cwiseAbs().maxCoeff());
  MomentMatch m;
  const double eps = std::numeric_limits<double>::epsilon();
  for (unsigned trial = 0; trial < 6; ++trial) {
    Vector mu = ::gpilqg::test::random_vector(3, -1.0, 1.0, 300 + trial);
    if (trial == 5) mu = gp.inputs.row(17).transpose();  // at a training input
    matcher.propagate(mu, Matrix::Zero(3, 3), m, MomentDerivatives::All);
    std::printf("  mu %u: S = [% .6e % .6e; % .6e % .6e]\n", trial, m.covariance(0, 0), m.covariance(0, 1),
                m.covariance(1, 0), m.covariance(1, 1));
    EXPECT_LT(std::abs(m.covariance(0, 1)), 1e-10) << "trial " << trial;
    EXPECT_EQ(m.covariance(0, 1), m.covariance(1, 0));
    for (int a = 0; a < 2; ++a) {
      // Reference: the stable latent variance sf^2 - ||L^-1 k||^2. The matcher only sees Kinv, whose
      // entries (up to ~1e8 / sf^2 here) already carry rounding: one ulp on each entry moves
      // k' Kinv k by up to ~eps |k|' |Kinv| |k|, so that is the accuracy any method reading Kinv can
      // reach (it is 1e3..1e4 x the latent variance's own size scale 1e-12 here, and ~1e-10 in
      // absolute terms); before the fix the error was ~1e-4.
      const Vector k = gp.kernel_column(a, mu);
      const double sf2 = std::exp(2.0 * gp.outputs[a].log_signal_std);
      const Vector lk = ill.factors[a].triangularView<Eigen::Lower>().solve(k);
      const double reference = sf2 - lk.squaredNorm();
      const double from_kinv = sf2 - k.dot(gp.outputs[a].Kinv * k);
      const double data_limit = eps * k.cwiseAbs().dot(gp.outputs[a].Kinv.cwiseAbs() * k.cwiseAbs());
      std::printf("    output %d: S_aa %.10e, Cholesky %.10e (diff % .1e), sf^2 - k'Kinv k diff % .1e, "
                  "Kinv data limit %.1e\n",
                  a, m.covariance(a, a), reference, m.covariance(a, a) - reference,
                  m.covariance(a, a) - from_kinv, data_limit);
      EXPECT_GE(m.covariance(a, a), 0.0);
      const double tolerance = 1e-12 + 1e-8 * std::abs(reference) + data_limit;
      EXPECT_NEAR(m.covariance(a, a), reference, tolerance) << "output " << a << ", trial " << trial;
      EXPECT_NEAR(m.covariance(a, a), std::max(from_kinv, 0.0), tolerance) << "output " << a;
      EXPECT_NEAR(m.mean(a), gp.posterior_mean(a, mu), 1e-9 * std::sqrt(sf2));
    }
    // The derivatives of the off-diagonal entry vanish too at Sigma = 0 for d/dmu (S_01 = 0 for all mu).
    EXPECT_LT(m.dcovariance_dmu.row(1).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT(m.dcovariance_dmu.row(2).cwiseAbs().maxCoeff(), 1e-10);
  }
}

TEST(MomentMatching, NearlyNoiseFreeGpsGiveAPositiveSemidefiniteCovarianceForASmallSigma) {
  const IllConditionedGp ill = make_ill_conditioned_gp();
  const TestGp& gp = ill.gp;
  const SeArdMomentMatcher matcher = gp.matcher();
  MomentMatch m;
  for (unsigned trial = 0; trial < 6; ++trial) {
    const Vector mu = ::gpilqg::test::random_vector(3, -1.0, 1.0, 400 + trial);
    Matrix sigma = (trial == 2 ? 1e-7 : 1e-3) * Matrix::Identity(3, 3);
    if (trial >= 3) sigma = make_sigma(3, 0.03, 500 + trial, /*zero_index=*/trial == 5 ? 2 : -1);
    matcher.propagate(mu, sigma, m, MomentDerivatives::All);
    const Eigen::SelfAdjointEigenSolver<Matrix> eig(m.covariance);
    // First order in Sigma, S_ab ~ g_a' Sigma g_b + delta_ab E[v_a]: the cross term must agree with it.
    const double first_order = m.dmean_dmu.row(0).dot(sigma * m.dmean_dmu.row(1).transpose());
    std::printf("  trial %u: S = [% .6e % .6e; % .6e % .6e], eigenvalues %.3e %.3e, g0' Sigma g1 % .6e\n", trial,
                m.covariance(0, 0), m.covariance(0, 1), m.covariance(1, 0), m.covariance(1, 1),
                eig.eigenvalues()(0), eig.eigenvalues()(1), first_order);
    EXPECT_GE(eig.eigenvalues()(0), -1e-12) << "trial " << trial;
    EXPECT_NEAR(m.covariance(0, 1), first_order, 0.05 * std::abs(first_order) + 1e-9) << "trial " << trial;
    // The off-diagonal entry's derivatives against central differences (the diagonal's differences are
    // dominated by the Kinv rounding above, ~1e-10 / h). S_01 itself carries ~4e-12 of rounding
    // (~eps N |gamma|^2 |D|), i.e. ~4e-7 in a difference with h = 1e-5 (checked: the gap scales as 1/h
    // from h = 1e-6 to 1e-4), so the steps are larger: 1e-3 for mu, 1e-4 for Sigma (~1e-3 here).
    if (trial == 2) continue;  // the steps would exceed Sigma = 1e-7 I itself
    const auto s01 = [&](const Vector& x, const Matrix& sig) {
      MomentMatch r;
      matcher.propagate(x, sig, r);
      return Vector::Constant(1, r.covariance(0, 1));
    };
    const Matrix numeric_mu = numeric_jacobian([&](const Vector& x) { return s01(x, sigma); }, mu, 1e-3);
    const Matrix numeric_sigma = numeric_jacobian(
        [&](const Vector& x) { return s01(mu, x.reshaped(3, 3)); }, sigma.reshaped(), 1e-4);
    EXPECT_TRUE(matrices_near(m.dcovariance_dmu.row(1), numeric_mu, 1e-8, 1e-4)) << "trial " << trial;
    EXPECT_TRUE(matrices_near(m.dcovariance_dsigma.row(1), numeric_sigma, 1e-7, 1e-5)) << "trial " << trial;
    std::printf("    dS_01: max |analytic - central difference| d/dmu %.1e (largest %.2e), d/dSigma %.1e "
                "(largest %.2e)\n",
                (m.dcovariance_dmu.row(1) - numeric_mu).cwiseAbs().maxCoeff(),
                m.dcovariance_dmu.row(1).cwiseAbs().maxCoeff(),
                (m.dcovariance_dsigma.row(1) - numeric_sigma).cwiseAbs().maxCoeff(),
                m.dcovariance_dsigma.row(1).cwiseAbs().maxCoeff());
  }
}

TEST(MomentMatching, ANegativeExpectedVarianceIsClampedWithZeroDerivatives) {
  // Kinv tripled: sf^2 - tr(Kinv Q) ~ -2 sf^2 < 0, so V_0 is clamped at 0 and S_00 is the covariance of
  // the posterior mean alone, with its derivatives (V_0 contributes none).
  TestGp gp = make_gp(12, 3, 2, 26);
  gp.outputs[0].Kinv *= 3.0;
  Vector mu(3);
  mu << 0.1, -0.2, 0.3;
  MomentMatch m;
  gp.matcher().propagate(mu, Matrix::Zero(3, 3), m);
  EXPECT_EQ(m.covariance(0, 0), 0.0);
  EXPECT_NEAR(m.covariance(1, 1), gp.posterior_variance(1, mu), 1e-12);
  check_gp_derivatives(gp, mu, make_sigma(3, 0.3, 9), "clamped V_0");
}

// ------------------------------------------------------------------------------------------------
// Workspace reuse, skipping derivatives, the conditioning helper

TEST(MomentMatching, ReusedResultMatchesAFreshOneAndDerivativesCanBeSkipped) {
  const TestGp gp = make_gp(18, 3, 3, 31);
  const SeArdMomentMatcher matcher = gp.matcher();
  const Vector mu1 = ::gpilqg::test::random_vector(3, -0.5, 0.5, 1);
  const Vector mu2 = ::gpilqg::test::random_vector(3, -0.5, 0.5, 2);
  const Matrix sigma1 = make_sigma(3, 0.3, 1);
  const Matrix sigma2 = make_sigma(3, 0.5, 2, 0);

  MomentMatch reused;
  matcher.propagate(mu1, sigma1, reused, MomentDerivatives::All);
  matcher.propagate(mu2, sigma2, reused, MomentDerivatives::None);
  EXPECT_FALSE(reused.has_derivatives);
  MomentMatch fresh;
  matcher.propagate(mu2, sigma2, fresh, MomentDerivatives::All);
  EXPECT_EQ(reused.mean, fresh.mean);
  EXPECT_EQ(reused.covariance, fresh.covariance);
  EXPECT_EQ(reused.cross_covariance, fresh.cross_covariance);
  matcher.propagate(mu2, sigma2, reused, MomentDerivatives::All);
  EXPECT_TRUE(reused.has_derivatives);
  EXPECT_EQ(reused.dcovariance_dsigma, fresh.dcovariance_dsigma);
  EXPECT_EQ(reused.dcross_dsigma, fresh.dcross_dsigma);
  EXPECT_EQ(reused.dmean_dsigma, fresh.dmean_dsigma);
  EXPECT_EQ(reused.covariance, reused.covariance.transpose());
}

/// Every result block of two propagations, compared bit for bit.
void expect_identical(const MomentMatch& a, const MomentMatch& b, const std::string& label) {
  EXPECT_EQ(a.mean, b.mean) << label;
  EXPECT_EQ(a.covariance, b.covariance) << label;
  EXPECT_EQ(a.cross_covariance, b.cross_covariance) << label;
  EXPECT_EQ(a.has_derivatives, b.has_derivatives) << label;
  if (!a.has_derivatives || !b.has_derivatives) return;
  EXPECT_EQ(a.dmean_dmu, b.dmean_dmu) << label;
  EXPECT_EQ(a.dmean_dsigma, b.dmean_dsigma) << label;
  EXPECT_EQ(a.dcovariance_dmu, b.dcovariance_dmu) << label;
  EXPECT_EQ(a.dcovariance_dsigma, b.dcovariance_dsigma) << label;
  EXPECT_EQ(a.dcross_dmu, b.dcross_dmu) << label;
  EXPECT_EQ(a.dcross_dsigma, b.dcross_dsigma) << label;
}

TEST(MomentMatching, TwoThreadsGiveBitIdenticalResults) {
  // Shared centres (N = 300, E = 3: 6 pairs of 300 x 300) and per-output centres of different sizes
  // (N_a = 260, 190, 120), both above the size from which the pairs are shared out.
  const TestGp shared = make_gp(300, 3, 3, 25, /*spread=*/3.0);
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  for (int a = 0; a < 3; ++a) {
    const TestGp one = make_gp(260 - 70 * a, 3, 1, 40 + a, 3.0);
    centres.push_back(one.inputs);
    outputs.push_back(one.outputs[0]);
  }
  const SeArdMomentMatcher per_output(centres, outputs);
  const SeArdMomentMatcher shared_matcher = shared.matcher();
  Vector mu(3);
  mu << 0.2, 0.1, -0.1;
  for (const SeArdMomentMatcher* matcher : {&shared_matcher, &per_output}) {
    MomentMatch one, two;
    two.threads = 2;
    for (const Matrix& sigma : {make_sigma(3, 0.3, 6, 2), Matrix(Matrix::Zero(3, 3)), make_sigma(3, 0.8, 7)}) {
      for (const auto derivatives : {MomentDerivatives::All, MomentDerivatives::None}) {
        matcher->propagate(mu, sigma, one, derivatives);
        matcher->propagate(mu, sigma, two, derivatives);
        expect_identical(one, two, matcher == &shared_matcher ? "shared centres" : "per-output centres");
      }
    }
    EXPECT_EQ(two.fork_join.helpers(), 1) << "the second thread was used";
    EXPECT_EQ(one.fork_join.helpers(), 0);
  }
  // Small problems stay on the calling thread.
  const TestGp small = make_gp(18, 3, 3, 31);
  MomentMatch m;
  m.threads = 2;
  small.matcher().propagate(mu, make_sigma(3, 0.3, 1), m, MomentDerivatives::All);
  EXPECT_EQ(m.fork_join.helpers(), 0);
}

TEST(MomentMatching, AnErrorOnTheHelperThreadReachesTheCaller) {
  const TestGp gp = make_gp(300, 3, 3, 25, 3.0);
  const SeArdMomentMatcher matcher = gp.matcher();
  MomentMatch m;
  m.threads = 2;
  const Vector mu = Vector::Zero(3);
  // Outputs 1 (and the pairs) run on the helper: every Rt fails there and here alike.
  expect_invalid([&] { matcher.propagate(mu, -100.0 * Matrix::Identity(3, 3), m, MomentDerivatives::All); },
                 "positive semidefinite");
  EXPECT_FALSE(m.has_derivatives);
  MomentMatch reference;
  matcher.propagate(mu, 0.1 * Matrix::Identity(3, 3), m, MomentDerivatives::All);
  matcher.propagate(mu, 0.1 * Matrix::Identity(3, 3), reference, MomentDerivatives::All);
  expect_identical(m, reference, "after the error");
}

TEST(MomentMatching, OnlyTheSymmetricPartOfSigmaIsRead) {
  const TestGp gp = make_gp(12, 3, 2, 32);
  const SeArdMomentMatcher matcher = gp.matcher();
  const Vector mu = Vector::Constant(3, 0.1);
  const Matrix sigma = make_sigma(3, 0.4, 5);
  Matrix skewed = sigma;
  skewed(0, 1) += 0.05;
  skewed(1, 0) -= 0.05;
  MomentMatch a, b;
  matcher.propagate(mu, sigma, a);
  matcher.propagate(mu, skewed, b);
  EXPECT_TRUE(matrices_near(a.covariance, b.covariance, 1e-15, 1e-13));
  EXPECT_TRUE(matrices_near(a.cross_covariance, b.cross_covariance, 1e-15, 1e-13));
}

TEST(MomentMatching, ConditioningHelperAgreesWithDirectConstruction) {
  const TestGp gp = make_gp(15, 2, 1, 33);
  // Recover y from beta: y = (K + sn^2 I) beta, then condition again with the helper.
  const SeArdOutput& o = gp.outputs[0];
  const Eigen::LLT<Matrix> kinv_factor(o.Kinv);
  const Vector y = kinv_factor.solve(o.beta);
  const SeArdOutput helper = condition_se_ard_output(gp.inputs, y, o.log_lengthscales, o.log_signal_std,
                                                     std::log(0.1));
  EXPECT_TRUE(matrices_near(helper.beta, o.beta, 1e-8, 1e-8));
  EXPECT_TRUE(matrices_near(helper.Kinv, o.Kinv, 1e-8, 1e-8));
}

// ------------------------------------------------------------------------------------------------
// 4. Validation

TEST(MomentMatching, ConstructionValidatesSizesAndValues) {
  const TestGp gp = make_gp(8, 3, 2, 41);
  expect_invalid([&] { SeArdMomentMatcher(Matrix(0, 3), gp.outputs); }, "inputs");
  expect_invalid([&] { SeArdMomentMatcher(gp.inputs, {}); }, "outputs is empty");
  {
    auto outputs = gp.outputs;
    outputs[1].log_lengthscales.resize(2);
    expect_invalid([&] { SeArdMomentMatcher(gp.inputs, outputs); }, "outputs[1].log_lengthscales");
  }
  {
    auto outputs = gp.outputs;
    outputs[0].beta.resize(7);
    expect_invalid([&] { SeArdMomentMatcher(gp.inputs, outputs); }, "outputs[0].beta");
  }
  {
    auto outputs = gp.outputs;
    outputs[1].Kinv.resize(8, 7);
    expect_invalid([&] { SeArdMomentMatcher(gp.inputs, outputs); }, "outputs[1].Kinv");
  }
  {
    auto outputs = gp.outputs;
    outputs[1].beta(3) = NAN;
    expect_invalid([&] { SeArdMomentMatcher(gp.inputs, outputs); }, "outputs[1].beta");
  }
  {
    auto outputs = gp.outputs;
    outputs[0].log_signal_std = INFINITY;
    expect_invalid([&] { SeArdMomentMatcher(gp.inputs, outputs); }, "outputs[0].log_signal_std");
  }
  {
    Matrix inputs = gp.inputs;
    inputs(2, 1) = NAN;
    expect_invalid([&] { SeArdMomentMatcher(inputs, gp.outputs); }, "inputs");
  }
}

TEST(MomentMatching, PropagateValidatesSizesAndValues) {
  const TestGp gp = make_gp(8, 3, 2, 42);
  const SeArdMomentMatcher matcher = gp.matcher();
  MomentMatch m;
  const Vector mu = Vector::Zero(3);
  const Matrix sigma = 0.1 * Matrix::Identity(3, 3);
  expect_invalid([&] { matcher.propagate(Vector::Zero(2), sigma, m); }, "mu has 2 entries");
  expect_invalid([&] { matcher.propagate(mu, Matrix::Zero(3, 2), m); }, "Sigma is 3 x 2");
  expect_invalid([&] { matcher.propagate(Vector::Constant(3, NAN), sigma, m); }, "mu has a non-finite");
  Matrix bad = sigma;
  bad(1, 2) = INFINITY;
  expect_invalid([&] { matcher.propagate(mu, bad, m, MomentDerivatives::All); }, "Sigma has a non-finite");
  expect_invalid([&] { matcher.propagate(mu, -100.0 * Matrix::Identity(3, 3), m); }, "positive semidefinite");
  // Still usable after the errors.
  matcher.propagate(mu, sigma, m, MomentDerivatives::All);
  EXPECT_TRUE(m.covariance.allFinite());
}

}  // namespace
}  // namespace gpilqg::gp::test
