#pragma once
/// @file moment_matching_checks.hpp
/// Checks every MomentMatcher (moment_matcher.hpp) must pass, shared by the SE-ARD, FITC and SSGP
/// moment-matching tests:
///  - Monte Carlo: z ~ N(mu, Sigma), the model's own posterior mean m_a(z) and latent variance v_a(z)
///    per sample (the integrand), and M, S = Cov[m(z)] + diag E[v(z)], C = Cov[z, m(z)] each within
///    4 standard errors of the sample estimate;
///  - central differences of [M; vec S; vec C] for every derivative block, one Sigma entry at a time
///    and in symmetric pairs, plus the symmetries of the layout;
///  - for a matcher built from fitted backends (moment_matcher_for): at Sigma = 0 the moments are the
///    models' own predictions, and both checks above with those predictions as the integrand.

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp::test {

/// m_a(z) into mean (E) and v_a(z) into variance (E) at one input z.
using PosteriorAtPoint = std::function<void(const Vector& z, Vector& mean, Vector& variance)>;

/// [M; vec S; vec C] as one vector, for finite differences.
Vector stacked_moments(const MomentMatcher& matcher, const Vector& mu, const Matrix& sigma);

/// A correlated covariance L L' (D x D); zero_index >= 0 zeroes that row and column (a deterministic
/// input such as a control).
Matrix make_sigma(int d, double scale, unsigned seed, int zero_index = -1);

struct MonteCarloCheck {
  double worst_z = 0.0;  ///< largest |analytic - MC| / SE seen
};

/// Compares the moments at (mu, Sigma) with `samples` draws z ~ N(mu, Sigma) of `posterior`, each
/// quantity within 4 standard errors (SE from the sample variance of the per-sample terms). Prints
/// the numbers under `label`.
MonteCarloCheck check_against_monte_carlo(const MomentMatcher& matcher, const PosteriorAtPoint& posterior,
                                          const Vector& mu, const Matrix& sigma, int samples,
                                          const std::string& label);

/// Tolerances of a central-difference check: |analytic - numeric| <= abs + rel |numeric|.
struct DifferenceTolerance {
  double step = 1e-5;
  double abs = 1e-8;
  double rel = 1e-6;
};

/// Every derivative block of `matcher` at (mu, Sigma) against central differences, one Sigma entry
/// at a time and symmetric pairs; d/dSigma_ij == d/dSigma_ji, and S's rows (a, b) and (b, a) agree.
void check_derivatives(const MomentMatcher& matcher, const Vector& mu, const Matrix& sigma, const std::string& label,
                       const DifferenceTolerance& tolerance = {});

/// Two smooth targets of N = 60 inputs in [-1.5, 1.5]^3 with noise 0.02, and fixed per-output
/// hyperparameters [log l (3); log sf; log sn] (sn = 0.05), for conditioning sparse backends.
struct TwoOutputData {
  Matrix inputs;                   ///< N x 3
  Matrix targets;                  ///< N x 2
  std::vector<Vector> hyper;       ///< 2 entries of 5
};
TwoOutputData two_output_data();

/// Fitted GPs, one per output, and the moment matcher moment_matcher_for builds from them.
struct FittedOutputs {
  std::vector<std::unique_ptr<FittedGp>> models;
  std::shared_ptr<const MomentMatcher> matcher;

  explicit FittedOutputs(std::vector<std::unique_ptr<FittedGp>> fitted);
  /// The Monte Carlo integrand: each model's own prediction (mean, latent variance).
  PosteriorAtPoint posterior() const;
};

/// E = 2 FITC GPs on two_output_data(), conditioned at its fixed hyperparameters with their own
/// pseudo-inputs (M = 8 and 11, drawn in the data box).
FittedOutputs fitc_outputs();
/// E = 2 SSGP GPs on two_output_data(), conditioned at its fixed hyperparameters with their own
/// spectral points (m = 10 and 7, W ~ N(0, I)).
FittedOutputs ssgp_outputs();

/// At Sigma = 0 (four means, one outside the data): M_a, S_aa and dM_a/dmu are the models'
/// predictions (mean, latent variance, mean gradient), S's off-diagonal and C exactly 0.
void expect_point_input_is_the_prediction(const FittedOutputs& fits, const std::string& label);

/// For D = 3: Monte Carlo (1e5 samples of the models' predictions; full Sigma and one with a zero row)
/// and central differences (full Sigma, a zero row, Sigma = 0) at fixed inputs.
void check_moments_and_derivatives(const FittedOutputs& fits, const std::string& label);

/// Expects f() to throw std::invalid_argument whose message contains `fragment`.
template <class F>
void expect_invalid(F&& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning '" << fragment << "'";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
        << "message '" << error.what() << "' does not mention '" << fragment << "'";
  }
}

}  // namespace gpilqg::gp::test
