/// FITC serving PDDP: exact moment matching of FITC posteriors (each output its own pseudo-inputs)
/// through SeArdMomentMatcher's per-output centres (moment_matcher_for, fitted_moment_matcher.hpp),
/// against independent references:
///  1. Sigma = 0: the FITC model's own prediction (FittedGp::predict), mean and latent variance;
///  2. Monte Carlo with 1e5 samples of the FITC prediction: M, S = Cov[m] + diag E[v], C;
///  3. every derivative against central differences (2 and 3: moment_matching_checks.hpp);
///  4. the native per-output centres against the stacked shared form (all centres in one X, zero-padded
///     beta, block-embedded Kinv), and, with all centres equal, against the shared-input constructor.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/moment_matching.hpp"
#include "moment_matching_checks.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::test {
namespace {

using ::gpilqg::test::matrices_near;

constexpr int kFitcInputs = 3;

TEST(FitcMomentMatching, ServesThroughPerOutputCentres) {
  const FittedOutputs pair = fitc_outputs();
  const auto* se = dynamic_cast<const SeArdMomentMatcher*>(pair.matcher.get());
  ASSERT_NE(se, nullptr);
  EXPECT_EQ(se->input_dim(), kFitcInputs);
  EXPECT_EQ(se->output_dim(), 2);
  EXPECT_EQ(se->training_size(0), 8);
  EXPECT_EQ(se->training_size(1), 11);
}

TEST(FitcMomentMatching, DeterministicInputIsTheFitcPrediction) {
  expect_point_input_is_the_prediction(fitc_outputs(), "FITC");
}

TEST(FitcMomentMatching, AgreesWithMonteCarloAndCentralDifferences) {
  check_moments_and_derivatives(fitc_outputs(), "FITC");
}

// ------------------------------------------------------------------------------------------------
// The native per-output centres against equivalent shared forms

/// The stacked shared form of per-output centres: X = [X_0; X_1; ...], output a's beta zero outside
/// its own block of rows and its Kinv embedded in the diagonal block. It describes the same GPs (a
/// zero weight drops a centre), at sum_a N_a centres per output.
SeArdMomentMatcher stacked(const std::vector<Matrix>& centres, const std::vector<SeArdOutput>& outputs) {
  Eigen::Index total = 0;
  for (const Matrix& x : centres) total += x.rows();
  Matrix x(total, centres[0].cols());
  std::vector<SeArdOutput> padded;
  Eigen::Index offset = 0;
  for (std::size_t a = 0; a < centres.size(); ++a) {
    const Eigen::Index n = centres[a].rows();
    x.middleRows(offset, n) = centres[a];
    SeArdOutput o = outputs[a];
    o.beta = Vector::Zero(total);
    o.beta.segment(offset, n) = outputs[a].beta;
    o.Kinv = Matrix::Zero(total, total);
    o.Kinv.block(offset, offset, n, n) = outputs[a].Kinv;
    padded.push_back(std::move(o));
    offset += n;
  }
  return SeArdMomentMatcher(std::move(x), std::move(padded));
}

/// All moments and derivative blocks of two matchers at (mu, Sigma), to `tolerance` (relative to 1).
void expect_same_moments(const MomentMatcher& a, const MomentMatcher& b, const Vector& mu, const Matrix& sigma,
                         double tolerance) {
  MomentMatch ma, mb;
  a.propagate(mu, sigma, ma, MomentDerivatives::All);
  b.propagate(mu, sigma, mb, MomentDerivatives::All);
  EXPECT_TRUE(matrices_near(ma.mean, mb.mean, tolerance, tolerance));
  for (Matrix MomentMatch::*block : {&MomentMatch::covariance, &MomentMatch::cross_covariance, &MomentMatch::dmean_dmu,
                                     &MomentMatch::dmean_dsigma, &MomentMatch::dcovariance_dmu,
                                     &MomentMatch::dcovariance_dsigma, &MomentMatch::dcross_dmu, &MomentMatch::dcross_dsigma})
    EXPECT_TRUE(matrices_near(ma.*block, mb.*block, tolerance, tolerance));
}

/// The per-output centres and SE outputs that moment_matcher_for reads from the FITC fits.
void fitc_centres(const FittedOutputs& pair, std::vector<Matrix>& centres, std::vector<SeArdOutput>& outputs) {
  for (const auto& model : pair.models) {
    const FitcPredictor* p = fitc_posterior(*model);
    ASSERT_NE(p, nullptr);
    const Vector& h = model->parameters();
    centres.push_back(p->inducing_inputs());
    outputs.push_back(SeArdOutput{h.head(kFitcInputs), h(kFitcInputs), p->beta(), -p->variance_matrix()});
  }
}

TEST(FitcMomentMatching, PerOutputCentresEqualTheStackedSharedForm) {
  const FittedOutputs pair = fitc_outputs();
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  fitc_centres(pair, centres, outputs);
  const SeArdMomentMatcher shared = stacked(centres, outputs);
  Vector mu(kFitcInputs);
  mu << 0.1, 0.3, -0.4;
  expect_same_moments(*pair.matcher, shared, mu, make_sigma(kFitcInputs, 0.4, 11), 1e-10);
  expect_same_moments(*pair.matcher, shared, mu, make_sigma(kFitcInputs, 0.4, 12, /*zero_index=*/0), 1e-10);
  expect_same_moments(*pair.matcher, shared, mu, Matrix::Zero(kFitcInputs, kFitcInputs), 1e-10);
}

TEST(SeArdMomentMatching, LargePerOutputCentreSetsEqualTheStackedSharedForm) {
  // N_a = 140 and 133 (> 128: the tiled products on views of the pair buffers), different inputs.
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  for (int a = 0; a < 2; ++a) {
    const int n = a == 0 ? 140 : 133;
    const Matrix x = ::gpilqg::test::random_vector(n * kFitcInputs, -3.0, 3.0, 50 + a).reshaped(n, kFitcInputs);
    Vector y(n);
    for (int i = 0; i < n; ++i) y(i) = std::sin(x(i, 0) + a) + 0.2 * x(i, 1) * x(i, 2);
    outputs.push_back(condition_se_ard_output(x, y, Vector::Constant(kFitcInputs, std::log(1.0 + 0.2 * a)), 0.1 * a,
                                              std::log(0.1)));
    centres.push_back(x);
  }
  const SeArdMomentMatcher native(centres, outputs);
  const SeArdMomentMatcher shared = stacked(centres, outputs);
  Vector mu(kFitcInputs);
  mu << 0.2, -0.1, 0.3;
  expect_same_moments(native, shared, mu, make_sigma(kFitcInputs, 0.3, 13, /*zero_index=*/2), 1e-10);
}

TEST(SeArdMomentMatching, EqualPerOutputCentresEqualTheSharedPath) {
  const FittedOutputs pair = fitc_outputs();
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  fitc_centres(pair, centres, outputs);
  // Both outputs on output 0's pseudo-inputs (output 1's weights on 8 centres: any numbers do).
  outputs[1].beta = outputs[1].beta.head(8).eval();
  outputs[1].Kinv = outputs[1].Kinv.topLeftCorner(8, 8).eval();
  const SeArdMomentMatcher per_output(std::vector<Matrix>{centres[0], centres[0]}, outputs);
  const SeArdMomentMatcher shared(centres[0], outputs);
  Vector mu(kFitcInputs);
  mu << -0.2, 0.1, 0.4;
  expect_same_moments(per_output, shared, mu, make_sigma(kFitcInputs, 0.4, 14), 1e-10);
}

TEST(SeArdMomentMatching, PerOutputConstructionValidatesTheCentres) {
  const FittedOutputs pair = fitc_outputs();
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  fitc_centres(pair, centres, outputs);
  expect_invalid([&] { SeArdMomentMatcher(std::vector<Matrix>{centres[0]}, outputs); }, "centres has 1 matrices for 2 outputs");
  expect_invalid([&] { SeArdMomentMatcher(std::vector<Matrix>{centres[0], Matrix(11, 2)}, outputs); }, "centres[1] has 2 columns");
  expect_invalid([&] { SeArdMomentMatcher(std::vector<Matrix>{centres[0], Matrix(0, 3)}, outputs); }, "centres[1] is 0 x 3");
  expect_invalid([&] { SeArdMomentMatcher(std::vector<Matrix>{centres[0], centres[0]}, outputs); },
                 "outputs[1].beta has 11 entries, expected N = 8 (rows of centres[1])");
  Matrix bad = centres[1];
  bad(2, 1) = NAN;
  expect_invalid([&] { SeArdMomentMatcher(std::vector<Matrix>{centres[0], bad}, outputs); }, "centres[1] has a non-finite entry");
}

}  // namespace
}  // namespace gpilqg::gp::test
