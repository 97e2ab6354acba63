#pragma once
/// @file metrics.hpp
/// Standard scores of probabilistic regression (GPML book section 2.5), as used for the benchmark data
/// (data/gp-benchmarks/README.md) and by `gpilqg profile`.
///
///   SMSE = mean((y - mu)^2) / var(y_test)                       (var divides by n)
///   MNLP = mean(0.5 log(2 pi s2) + (y - mu)^2 / (2 s2))          (s2 includes the noise)
///   MSLL = MNLP - mean(0.5 log(2 pi v) + (y - m)^2 / (2 v))      (m, v: training targets' mean and
///                                                                 divide-by-n variance)

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp {

struct RegressionScores {
  double smse = 0.0;
  double mnlp = 0.0;
  double msll = 0.0;
};

/// Throws std::invalid_argument when sizes differ, a vector is empty, the test targets are constant,
/// or a predictive variance is not positive.
double standardised_mean_squared_error(const VectorCRef& targets, const VectorCRef& mean);
double mean_negative_log_probability(const VectorCRef& targets, const VectorCRef& mean,
                                     const VectorCRef& predictive_variance);
double mean_standardised_log_loss(const VectorCRef& targets, const VectorCRef& mean,
                                  const VectorCRef& predictive_variance, const VectorCRef& training_targets);
/// All three; `predictive_variance` is the latent variance plus the noise variance.
RegressionScores regression_scores(const VectorCRef& targets, const VectorCRef& mean,
                                   const VectorCRef& predictive_variance, const VectorCRef& training_targets);

}  // namespace gpilqg::gp
