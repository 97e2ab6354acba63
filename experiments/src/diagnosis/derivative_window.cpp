#include "gpilqg/experiments/diagnosis/derivative_window.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/savitzky_golay.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"

namespace gpilqg::diagnosis {

namespace {

/// The smallest odd window above `order`: the shortest Savitzky-Golay fit of that degree.
int smallest_window(int order) { return order % 2 == 0 ? order + 1 : order + 2; }

/// C(2k, k), the variance of the k-th difference of unit white noise.
double central_binomial(int k) {
  double c = 1.0;
  for (int j = 1; j <= k; ++j) c = c * static_cast<double>(k + j) / static_cast<double>(j);
  return c;
}

/// The centred weights of `filter`, zero-padded to half-width `half` (>= the filter's own).
Vector centred_weights(const SavitzkyGolayDerivative& filter, int half) {
  const int own = filter.window() / 2;
  Vector c = Vector::Zero(2 * half + 1);
  c.segment(half - own, filter.window()) = filter.weights(own);
  return c;
}

/// The centred estimate (per unit step, not divided by dt) at sample i of y.
double centred_estimate(const Vector& c, const Vector& y, Eigen::Index i) {
  const Eigen::Index half = c.size() / 2;
  return c.dot(y.segment(i - half, c.size()));
}

/// R_hat(w) of the file comment with the noise level `sigma`; +inf when no sample has both filters
/// centred.
double estimated_risk(const std::vector<Vector>& segments, double dt, int order, int derivative, int window,
                      double sigma) {
  const int needed = shortest_differentiable_segment(order);
  const double step = derivative == 2 ? dt * dt : dt;
  const double noise_variance = sigma * sigma / (step * step);  // per unit squared weight
  const SavitzkyGolayDerivative filter(window, order, derivative);
  // The reference: degree order + 2 on the same window (or the shortest it has).
  const SavitzkyGolayDerivative reference(std::max(window, needed), order + 2, derivative);
  const int half = reference.window() / 2;
  const Vector c = centred_weights(filter, half);
  const Vector difference = c - centred_weights(reference, half);
  double sum = 0.0;
  Eigen::Index count = 0;
  for (const Vector& y : segments)
    for (Eigen::Index i = half; i + half < y.size(); ++i) {
      const double d = centred_estimate(difference, y, i) / step;
      sum += d * d;
      ++count;
    }
  if (count == 0) return std::numeric_limits<double>::infinity();
  const double squared_bias = std::max(0.0, sum / static_cast<double>(count) - noise_variance * difference.squaredNorm());
  return noise_variance * c.squaredNorm() + squared_bias;
}

}  // namespace

double difference_noise_std(const std::vector<Vector>& segments) {
  double best = std::numeric_limits<double>::infinity();
  for (int k = 2; k <= 6; ++k) {
    double sum = 0.0;
    Eigen::Index count = 0;
    for (const Vector& y : segments) {
      if (y.size() <= k) continue;
      Vector d = y;
      for (int r = 0; r < k; ++r) d = (d.tail(d.size() - 1) - d.head(d.size() - 1)).eval();
      sum += d.squaredNorm();
      count += d.size();
    }
    if (count > 0) best = std::min(best, sum / (static_cast<double>(count) * central_binomial(k)));
  }
  if (!std::isfinite(best))
    throw DataProblem("noise estimate: no segment has 3 samples; expected at least one");
  return std::sqrt(best);
}

int shortest_differentiable_segment(int order) { return smallest_window(order + 2); }

DerivativeWindow choose_derivative_window(const std::vector<Vector>& segments, double dt, int order, int derivative) {
  if (!(std::isfinite(dt) && dt > 0.0))
    throw std::invalid_argument(fmt::format("derivative window: dt = {}; expected a finite positive step", dt));
  if (derivative < 1 || derivative > 2)
    throw std::invalid_argument(fmt::format("derivative window: derivative {}; expected 1 or 2", derivative));
  if (order < derivative)
    throw std::invalid_argument(fmt::format("derivative window: order {}; expected >= {}", order, derivative));
  if (segments.empty()) throw std::invalid_argument("derivative window: no samples");
  const int needed = shortest_differentiable_segment(order);
  Eigen::Index shortest = std::numeric_limits<Eigen::Index>::max();
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (segments[s].size() < needed)
      throw DataProblem(fmt::format(
          "derivative window: segment {} has {} samples; expected at least {} (the reference differentiator of "
          "order {} spans {})", s, segments[s].size(), needed, order + 2, needed));
    if (!segments[s].allFinite())
      throw DataProblem(fmt::format("derivative window: segment {} has a sample that is not finite", s));
    shortest = std::min(shortest, segments[s].size());
  }

  const double sigma = difference_noise_std(segments);

  DerivativeWindow best;
  best.order = order;
  best.derivative = derivative;
  best.noise_std = sigma;
  best.risk = std::numeric_limits<double>::infinity();
  int candidates = 0;
  for (int h = smallest_window(order) / 2; 2 * h + 1 <= shortest;
       h = std::max(h + 1, static_cast<int>(std::lround(1.2 * h)))) {
    const double risk = estimated_risk(segments, dt, order, derivative, 2 * h + 1, sigma);
    if (!std::isfinite(risk)) break;
    ++candidates;
    if (risk < best.risk) {
      best.window = 2 * h + 1;
      best.risk = risk;
      best.noise_gain = SavitzkyGolayDerivative(2 * h + 1, order, derivative).noise_gain(dt);
    } else if (risk > 4.0 * best.risk) {
      break;
    }
  }
  best.candidates = candidates;
  return best;
}

}  // namespace gpilqg::diagnosis
