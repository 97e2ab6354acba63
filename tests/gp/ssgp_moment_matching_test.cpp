/// SSGP serving PDDP: exact moment matching of sparse spectrum posteriors (ssgp_moment_matching.hpp)
/// against independent references:
///  1. Sigma = 0: the SSGP model's own prediction (FittedGp::predict), mean, latent variance, gradient;
///  2. Monte Carlo with 1e5 samples of the SSGP prediction: M, S = Cov[m] + diag E[v], C;
///  3. every derivative against central differences (2 and 3: moment_matching_checks.hpp);
///  4. a very wide input: the closed-form limit (every feature averages out, E[cos^2] = E[sin^2] = 1/2),
///     finite and without NaN; an input covariance far from PSD throws instead of returning NaN;
///  5. construction validation.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "gpilqg/gp/ssgp_moment_matching.hpp"
#include "moment_matching_checks.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::test {
namespace {

constexpr int kSsgpInputs = 3;

const SsgpPredictor& predictor(const FittedOutputs& pair, int a) {
  return *ssgp_posterior(*pair.models[static_cast<std::size_t>(a)]);
}

TEST(SsgpMomentMatching, ServesThroughTrigonometricFeatures) {
  const FittedOutputs pair = ssgp_outputs();
  ASSERT_NE(dynamic_cast<const SsgpMomentMatcher*>(pair.matcher.get()), nullptr);
  EXPECT_EQ(pair.matcher->input_dim(), kSsgpInputs);
  EXPECT_EQ(pair.matcher->output_dim(), 2);
}

TEST(SsgpMomentMatching, DeterministicInputIsTheSsgpPrediction) {
  expect_point_input_is_the_prediction(ssgp_outputs(), "SSGP");
}

TEST(SsgpMomentMatching, AgreesWithMonteCarloAndCentralDifferences) {
  check_moments_and_derivatives(ssgp_outputs(), "SSGP");
}

TEST(SsgpMomentMatching, DerivativesMatchCentralDifferencesForAWideInput) {
  // s' Sigma s up to ~20: Ch and Sh far from their small-kappa regime, p from exp() (|kappa| >= 1).
  // (Regression: p = e_r e_q / (1 + x) for every kappa left ~3e-10 of rounding in S here, as 1 + x
  // cancels for large |kappa|.)
  Vector mu(kSsgpInputs);
  mu << 0.3, -0.2, 0.5;
  check_derivatives(*ssgp_outputs().matcher, mu, make_sigma(kSsgpInputs, 2.0, 5), "SSGP wide Sigma");
}

TEST(SsgpMomentMatching, AVeryWideInputAveragesEveryFeatureOut) {
  // Sigma = 1e4 I: every E[cos s'z], E[sin s'z] and every sum and difference frequency's damping
  // is below 1e-100, except s_r - s_r = 0: Var[cos] + Var[sin] of one frequency is 1/2 + 1/2. So
  // M = 0, C = 0, S_ab = 0 (a != b) and S_aa = 1/2 |alpha_a|^2 + 1/2 tr(C_a) (no two frequencies coincide).
  const FittedOutputs pair = ssgp_outputs();
  MomentMatch m;
  pair.matcher->propagate(Vector::Constant(kSsgpInputs, 0.3), 1e4 * Matrix::Identity(kSsgpInputs, kSsgpInputs), m, MomentDerivatives::All);
  EXPECT_TRUE(m.dcovariance_dsigma.allFinite());
  EXPECT_LT(m.mean.cwiseAbs().maxCoeff(), 1e-100);
  EXPECT_LT(m.cross_covariance.cwiseAbs().maxCoeff(), 1e-90);
  EXPECT_LT(std::abs(m.covariance(0, 1)), 1e-100);
  for (int a = 0; a < 2; ++a) {
    const SsgpPredictor& p = predictor(pair, a);
    const double limit = 0.5 * p.alpha().squaredNorm() + 0.5 * p.variance_matrix().trace();
    EXPECT_NEAR(m.covariance(a, a), limit, 1e-12 * limit) << "output " << a;
  }
}

TEST(SsgpMomentMatching, ACovarianceFarFromPositiveSemidefiniteThrowsInsteadOfNaN) {
  const FittedOutputs pair = ssgp_outputs();
  MomentMatch m;
  expect_invalid([&] { pair.matcher->propagate(Vector::Zero(kSsgpInputs), -1e4 * Matrix::Identity(kSsgpInputs, kSsgpInputs), m); },
                 "overflowed");
  EXPECT_FALSE(m.has_derivatives);
  pair.matcher->propagate(Vector::Zero(kSsgpInputs), 0.1 * Matrix::Identity(kSsgpInputs, kSsgpInputs), m, MomentDerivatives::All);
  EXPECT_TRUE(m.has_derivatives);
}

TEST(SsgpMomentMatching, ConstructionValidatesSizesAndValues) {
  const FittedOutputs pair = ssgp_outputs();
  std::vector<SsgpOutput> outputs;
  for (int a = 0; a < 2; ++a) {
    const SsgpPredictor& p = predictor(pair, a);
    outputs.push_back(SsgpOutput{p.frequency_matrix(), p.alpha(), p.variance_matrix()});
  }
  expect_invalid([] { SsgpMomentMatcher(std::vector<SsgpOutput>{}); }, "outputs is empty");
  {
    auto bad = outputs;
    bad[1].frequencies = Matrix::Zero(7, 2);
    expect_invalid([&] { SsgpMomentMatcher{bad}; }, "outputs[1].frequencies has 2 columns");
  }
  {
    auto bad = outputs;
    bad[0].weights.resize(19);
    expect_invalid([&] { SsgpMomentMatcher{bad}; }, "outputs[0].weights has 19 entries, expected 2m = 20");
  }
  {
    auto bad = outputs;
    bad[1].variance.resize(14, 13);
    expect_invalid([&] { SsgpMomentMatcher{bad}; }, "outputs[1].variance is 14 x 13");
  }
  {
    auto bad = outputs;
    bad[1].weights(3) = NAN;
    expect_invalid([&] { SsgpMomentMatcher{bad}; }, "outputs[1].weights has a non-finite entry");
  }
  {
    auto bad = outputs;
    bad[0].frequencies.resize(0, kSsgpInputs);
    expect_invalid([&] { SsgpMomentMatcher{bad}; }, "outputs[0].frequencies is 0 x 3");
  }
  const SsgpMomentMatcher matcher(outputs);
  MomentMatch m;
  expect_invalid([&] { matcher.propagate(Vector::Zero(2), Matrix::Zero(kSsgpInputs, kSsgpInputs), m); }, "mu has 2 entries");
  expect_invalid([&] { matcher.propagate(Vector::Zero(kSsgpInputs), Matrix::Zero(kSsgpInputs, 2), m); }, "Sigma is 3 x 2");
}

}  // namespace
}  // namespace gpilqg::gp::test
