#include "gpilqg/experiments/diagnosis/whiteness.hpp"

#include <cmath>
#include <stdexcept>

#include "gpilqg/experiments/diagnosis/chi_square.hpp"

namespace gpilqg::diagnosis {

namespace {

void check_lag(int max_lag) {
  if (max_lag < 0) throw std::invalid_argument("autocorrelation: max_lag " + std::to_string(max_lag) + "; expected >= 0");
}

}  // namespace

std::vector<long> lag_pairs(const std::vector<int>& episode, int max_lag) {
  check_lag(max_lag);
  std::vector<long> out(static_cast<std::size_t>(max_lag) + 1, 0);
  const auto N = episode.size();
  for (std::size_t k = 0; k < out.size(); ++k)
    for (std::size_t t = 0; t + k < N; ++t) out[k] += episode[t] == episode[t + k] ? 1 : 0;
  return out;
}

Vector autocorrelation(const VectorCRef& series, const std::vector<int>& episode, int max_lag) {
  check_lag(max_lag);
  if (static_cast<std::size_t>(series.size()) != episode.size())
    throw std::invalid_argument("autocorrelation: " + std::to_string(series.size()) + " values but " +
                                std::to_string(episode.size()) + " episode labels");
  Vector out = Vector::Zero(max_lag + 1);
  const Eigen::Index N = series.size();
  if (N == 0) return out;
  const Vector centred = series.array() - series.mean();
  const double zero = centred.squaredNorm();
  if (!(zero > 0.0)) return out;
  out(0) = 1.0;
  for (int k = 1; k <= max_lag; ++k) {
    double sum = 0.0;
    for (Eigen::Index t = 0; t + k < N; ++t)
      if (episode[static_cast<std::size_t>(t)] == episode[static_cast<std::size_t>(t + k)]) sum += centred(t) * centred(t + k);
    out(k) = sum / zero;
  }
  return out;
}

double ljung_box(const VectorCRef& rho, const std::vector<long>& pairs, long samples) {
  const auto N = static_cast<double>(samples);
  double q = 0.0;
  for (Eigen::Index k = 1; k < rho.size() && static_cast<std::size_t>(k) < pairs.size(); ++k)
    if (pairs[static_cast<std::size_t>(k)] > 0) q += rho(k) * rho(k) / static_cast<double>(pairs[static_cast<std::size_t>(k)]);
  return N * (N + 2.0) * q;
}

Whiteness whiteness_test(const Transitions& data, const Matrix& residual, const std::vector<std::string>& names,
                         int max_lag, double level) {
  check_lag(max_lag);
  if (!(level > 0.0 && level < 1.0)) throw std::invalid_argument("whiteness: level must be in (0, 1)");
  const std::vector<int> rows = data.rows(true);
  std::vector<int> episode;
  episode.reserve(rows.size());
  for (int r : rows) episode.push_back(data.episode[static_cast<std::size_t>(r)]);
  const std::vector<long> pairs = lag_pairs(episode, max_lag);

  Whiteness out;
  out.max_lag = max_lag;
  out.samples = static_cast<long>(rows.size());
  out.level = level;
  out.band = 1.96 / std::sqrt(static_cast<double>(std::max(out.samples, 1L)));
  for (int k = 1; k <= max_lag; ++k) out.degrees_of_freedom += pairs[static_cast<std::size_t>(k)] > 0 ? 1 : 0;
  if (out.degrees_of_freedom > 0) out.critical_value = chi_square_quantile(1.0 - level, out.degrees_of_freedom);

  Vector series(static_cast<Eigen::Index>(rows.size()));
  for (Eigen::Index i = 0; i < residual.cols(); ++i) {
    for (std::size_t s = 0; s < rows.size(); ++s) series(static_cast<Eigen::Index>(s)) = residual(rows[s], i);
    StateWhiteness w;
    w.name = names.at(static_cast<std::size_t>(i));
    w.autocorrelation = autocorrelation(series, episode, max_lag);
    for (int k = 1; k <= max_lag; ++k) w.outside_band += std::abs(w.autocorrelation(k)) > out.band ? 1 : 0;
    if (out.degrees_of_freedom > 0) {
      w.ljung_box = ljung_box(w.autocorrelation, pairs, out.samples);
      w.p_value = chi_square_survival(w.ljung_box, out.degrees_of_freedom);
      w.white = w.ljung_box <= out.critical_value;
    }
    out.states.push_back(std::move(w));
  }
  return out;
}

}  // namespace gpilqg::diagnosis
