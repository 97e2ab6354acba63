#include "gpilqg/gp/metrics.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gpilqg::gp {

namespace {

void check_sizes(const VectorCRef& targets, const VectorCRef& other, const char* who, const char* what) {
  if (targets.size() == 0) throw std::invalid_argument(std::string(who) + ": no test targets");
  if (other.size() != targets.size())
    throw std::invalid_argument(std::string(who) + ": " + what + " has " + std::to_string(other.size()) +
                                " entries; expected one per test target (" + std::to_string(targets.size()) + ")");
}

double population_variance(const VectorCRef& v) { return (v.array() - v.mean()).square().mean(); }

/// mean over points of 0.5 log(2 pi s2) + (y - mu)^2 / (2 s2)
double mean_gaussian_loss(const VectorCRef& y, const Eigen::ArrayXd& mu, const Eigen::ArrayXd& s2) {
  return (0.5 * (2.0 * std::numbers::pi * s2).log() + (y.array() - mu).square() / (2.0 * s2)).mean();
}

}  // namespace

double standardised_mean_squared_error(const VectorCRef& targets, const VectorCRef& mean) {
  check_sizes(targets, mean, "standardised_mean_squared_error", "mean");
  const double variance = population_variance(targets);
  if (!(variance > 0.0))
    throw std::invalid_argument("standardised_mean_squared_error: test targets are constant; SMSE is undefined");
  return (targets - mean).squaredNorm() / static_cast<double>(targets.size()) / variance;
}

double mean_negative_log_probability(const VectorCRef& targets, const VectorCRef& mean,
                                     const VectorCRef& predictive_variance) {
  check_sizes(targets, mean, "mean_negative_log_probability", "mean");
  check_sizes(targets, predictive_variance, "mean_negative_log_probability", "predictive variance");
  if (!(predictive_variance.array() > 0.0).all())
    throw std::invalid_argument("mean_negative_log_probability: a predictive variance is not positive");
  return mean_gaussian_loss(targets, mean.array(), predictive_variance.array());
}

double mean_standardised_log_loss(const VectorCRef& targets, const VectorCRef& mean,
                                  const VectorCRef& predictive_variance, const VectorCRef& training_targets) {
  const double mnlp = mean_negative_log_probability(targets, mean, predictive_variance);
  if (training_targets.size() == 0)
    throw std::invalid_argument("mean_standardised_log_loss: no training targets");
  const double train_variance = population_variance(training_targets);
  if (!(train_variance > 0.0))
    throw std::invalid_argument("mean_standardised_log_loss: training targets are constant");
  const Eigen::Index n = targets.size();
  const double trivial = mean_gaussian_loss(targets, Eigen::ArrayXd::Constant(n, training_targets.mean()),
                                            Eigen::ArrayXd::Constant(n, train_variance));
  return mnlp - trivial;
}

RegressionScores regression_scores(const VectorCRef& targets, const VectorCRef& mean,
                                   const VectorCRef& predictive_variance, const VectorCRef& training_targets) {
  RegressionScores s;
  s.smse = standardised_mean_squared_error(targets, mean);
  s.mnlp = mean_negative_log_probability(targets, mean, predictive_variance);
  s.msll = mean_standardised_log_loss(targets, mean, predictive_variance, training_targets);
  return s;
}

}  // namespace gpilqg::gp
