#include "gpilqg/gp/hyperparameters.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg::gp {

double Hyperparameters::signal_variance() const { return std::exp(2.0 * log_signal_std); }
double Hyperparameters::noise_variance() const { return std::exp(2.0 * log_noise_std); }

Vector Hyperparameters::pack() const {
  const int d = input_dim();
  Vector theta(count(d));
  theta.head(d) = log_lengthscales;
  theta(signal_index(d)) = log_signal_std;
  theta(noise_index(d)) = log_noise_std;
  return theta;
}

Hyperparameters Hyperparameters::unpack(const VectorCRef& parameters, int input_dim) {
  if (input_dim < 1 || parameters.size() < count(input_dim))
    throw std::invalid_argument("Hyperparameters::unpack: parameter vector has " +
                                std::to_string(parameters.size()) + " entries; expected at least D + 2 = " +
                                std::to_string(count(input_dim)) + " for D = " + std::to_string(input_dim));
  for (int i = 0; i < count(input_dim); ++i)
    if (!std::isfinite(parameters(i)))
      throw std::invalid_argument("Hyperparameters::unpack: entry " + std::to_string(i) + " is " +
                                  std::to_string(parameters(i)) + "; expected finite log-space values");
  Hyperparameters h;
  h.log_lengthscales = parameters.head(input_dim);
  h.log_signal_std = parameters(signal_index(input_dim));
  h.log_noise_std = parameters(noise_index(input_dim));
  return h;
}

Hyperparameters Hyperparameters::from_paper(const VectorCRef& lambda_diagonal, double signal_std,
                                            double noise_std) {
  if (lambda_diagonal.size() == 0 || !(lambda_diagonal.array() > 0.0).all() || !lambda_diagonal.allFinite() ||
      !(signal_std > 0.0) || !(noise_std > 0.0) || !std::isfinite(signal_std) || !std::isfinite(noise_std))
    throw std::invalid_argument("Hyperparameters::from_paper: expected Lambda_dd > 0 and sf, sn > 0, finite");
  Hyperparameters h;
  h.log_lengthscales = (0.5 * lambda_diagonal.array()).sqrt().log().matrix();
  h.log_signal_std = std::log(signal_std);
  h.log_noise_std = std::log(noise_std);
  return h;
}

namespace {

/// Population standard deviation of each input column; 1 where a column is constant.
Vector input_spreads(const TrainingSet& data) {
  Vector spread(data.input_dim());
  for (int d = 0; d < data.input_dim(); ++d) {
    const auto column = data.inputs.col(d).array();
    const double s = std::sqrt((column - column.mean()).square().mean());
    spread(d) = s > 0.0 && std::isfinite(s) ? s : 1.0;
  }
  return spread;
}

double target_std(const TrainingSet& data) {
  const double s = std::sqrt((data.targets.array() - data.targets.mean()).square().mean());
  return s > 0.0 && std::isfinite(s) ? s : 1.0;
}

}  // namespace

Hyperparameters initial_hyperparameters(const TrainingSet& data) {
  Hyperparameters h;
  h.log_lengthscales = input_spreads(data).array().log().matrix();
  const double sy = target_std(data);
  h.log_signal_std = std::log(sy);
  h.log_noise_std = std::log(0.1 * sy);
  return h;
}

ParameterBounds hyperparameter_bounds(const TrainingSet& data, double min_noise_std, double min_noise_ratio) {
  const int d = data.input_dim();
  const Vector spread = input_spreads(data);
  const double sy = target_std(data);
  ParameterBounds b;
  b.lower.resize(Hyperparameters::count(d));
  b.upper.resize(Hyperparameters::count(d));
  b.lower.head(d) = (spread.array() * 1e-3).log().matrix();
  b.upper.head(d) = (spread.array() * kMaxLengthscaleOverSpread).log().matrix();
  b.lower(d) = std::log(1e-3 * sy);
  b.upper(d) = std::log(1e3 * sy);
  b.lower(d + 1) = std::log(std::max(min_noise_ratio * sy, min_noise_std));
  // A floor above 10 s_y (sensors noisier than the targets vary) fixes sn at the floor.
  b.upper(d + 1) = std::max(std::log(10.0 * sy), b.lower(d + 1));
  return b;
}

}  // namespace gpilqg::gp
