#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "gpilqg/experiments/diagnosis/whiteness.hpp"
#include "gpilqg/gp/backend_registry.hpp"

namespace gpilqg::diagnosis {

double fit_percent(const VectorCRef& y, const VectorCRef& y_hat) {
  const double error = (y - y_hat).norm();
  const double spread = (y.array() - y.mean()).matrix().norm();
  if (spread == 0.0) return error == 0.0 ? 100.0 : 0.0;
  return 100.0 * (1.0 - error / spread);
}

double rms(const VectorCRef& values, const std::vector<int>& rows) {
  if (rows.empty()) return values.size() == 0 ? 0.0 : std::sqrt(values.squaredNorm() / static_cast<double>(values.size()));
  double sum = 0.0;
  for (int r : rows) sum += values(r) * values(r);
  return std::sqrt(sum / static_cast<double>(rows.size()));
}

namespace {

Matrix inputs_of(const Transitions& data) {
  Matrix z(data.size(), data.x.cols() + data.u.cols());
  z << data.x, data.u;
  return z;
}

}  // namespace

ResidualGp fit_residual_gp(std::shared_ptr<const StepModel> simulator, const Transitions& data, const Matrix& residual,
                           const GpSettings& settings) {
  gp::BackendSettings backend_settings;
  backend_settings.exact_points = settings.points;
  backend_settings.inducing = settings.points;
  backend_settings.frequencies = settings.points;
  const auto backend = gp::make_backend(settings.backend, backend_settings);

  gp::ResidualData all{inputs_of(data), residual};
  const gp::ResidualData training = all.subset(data.rows(false));
  gp::ResidualModelOptions options;
  options.fit.restarts = settings.restarts;
  options.fit.seed = settings.seed;
  options.threads = settings.threads;
  auto model = std::make_shared<const gp::ResidualModel>(
      gp::ResidualModel::fit(std::move(simulator), training, *backend, options));

  const int n = static_cast<int>(residual.cols());
  ResidualGp out;
  out.noise_std.resize(n);
  out.signal_variance.resize(n);
  out.mean.resize(data.size(), n);
  out.variance.resize(data.size(), n);
  Vector mean, variance;
  for (int i = 0; i < n; ++i) {
    const gp::FittedGp& g = model->output(i);
    out.noise_std(i) = std::sqrt(g.noise_variance());
    out.signal_variance(i) = g.prior_variance();
    g.predict(all.inputs, mean, variance);
    out.mean.col(i) = mean;
    out.variance.col(i) = variance.cwiseMax(0.0);
  }
  out.model = std::move(model);
  return out;
}

Matrix gp_column_means(const Transitions& data, const Matrix& targets, const GpSettings& settings,
                       const Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>* left_out) {
  gp::BackendSettings backend_settings;
  backend_settings.exact_points = settings.points;
  backend_settings.inducing = settings.points;
  backend_settings.frequencies = settings.points;
  const auto backend = gp::make_backend(settings.backend, backend_settings);
  const Matrix z = inputs_of(data);
  const std::vector<int> training = data.rows(false);
  gp::FitOptions options;
  options.restarts = settings.restarts;
  Matrix out(data.size(), targets.cols());
  Vector mean, variance;
  for (Eigen::Index i = 0; i < targets.cols(); ++i) {
    const auto equation = [&](int t) { return left_out == nullptr || !(*left_out)(t, i); };
    std::vector<int> rows;
    std::copy_if(training.begin(), training.end(), std::back_inserter(rows), equation);
    if (rows.empty()) {  // no equation of this column to learn: nothing is predicted
      out.col(i).setZero();
      continue;
    }
    gp::TrainingSet all{z, targets.col(i)};
    options.seed = settings.seed + 7919u * static_cast<std::uint64_t>(i);
    const gp::FitResult fit = backend->fit(backend->select_training_points(all.subset(rows), settings.seed), options);
    fit.model->predict(z, mean, variance);
    for (Eigen::Index t = 0; t < mean.size(); ++t) out(t, i) = equation(static_cast<int>(t)) ? mean(t) : 0.0;
  }
  return out;
}

Vector gp_explained(const ResidualGp& gp, const Transitions& data, const Matrix& residual) {
  const std::vector<int> rows = data.rows(true);
  Vector out = Vector::Zero(residual.cols());
  for (Eigen::Index i = 0; i < residual.cols(); ++i) {
    double before = 0.0, after = 0.0;
    for (int r : rows) {
      before += residual(r, i) * residual(r, i);
      const double e = residual(r, i) - gp.mean(r, i);
      after += e * e;
    }
    out(i) = before > 0.0 ? 1.0 - after / before : 0.0;
  }
  return out;
}

Matrix gp_sensitivity(const ResidualGp& gp, const Transitions& data, const std::vector<int>& rows, int max_points) {
  const Matrix z = inputs_of(data);
  const auto n = static_cast<int>(data.x.cols());
  const auto d = static_cast<int>(z.cols());
  Matrix out = Matrix::Zero(n, d);
  if (rows.empty()) return out;
  const int stride = std::max(1, static_cast<int>(rows.size()) / std::max(1, max_points));
  std::vector<int> used;
  for (std::size_t k = 0; k < rows.size(); k += static_cast<std::size_t>(stride)) used.push_back(rows[k]);
  // std(z_j) over the rows used.
  Vector spread(d);
  for (int j = 0; j < d; ++j) {
    double mean = 0.0;
    for (int r : used) mean += z(r, j);
    mean /= static_cast<double>(used.size());
    double var = 0.0;
    for (int r : used) var += (z(r, j) - mean) * (z(r, j) - mean);
    spread(j) = std::sqrt(var / static_cast<double>(used.size()));
  }
  gp::Prediction p;
  const gp::PredictionRequest request{false, true};
  for (int i = 0; i < n; ++i) {
    const gp::FittedGp& g = gp.model->output(i);
    for (int r : used) {
      g.predict(z.row(r).transpose(), p, request);
      out.row(i) += p.mean_gradient.cwiseAbs().transpose();
    }
  }
  out /= static_cast<double>(used.size());
  for (int j = 0; j < d; ++j) out.col(j) *= spread(j);
  return out;
}

std::vector<BinnedResidual> bin_residuals(const Transitions& data, const Matrix& residual,
                                          const std::vector<std::string>& input_names, int bins) {
  const Matrix z = inputs_of(data);
  const auto n = residual.cols();
  std::vector<BinnedResidual> out;
  const int N = data.size();
  for (Eigen::Index j = 0; j < z.cols(); ++j) {
    BinnedResidual b;
    b.input = input_names.at(static_cast<std::size_t>(j));
    std::vector<double> sorted(z.col(j).data(), z.col(j).data() + N);
    std::sort(sorted.begin(), sorted.end());
    b.edges.resize(bins + 1);
    for (int k = 0; k <= bins; ++k) {
      const auto at = static_cast<std::size_t>(std::min<long>(N - 1, std::lround(static_cast<double>(k) * (N - 1) / bins)));
      b.edges(k) = sorted.empty() ? 0.0 : sorted[at];
    }
    b.rms = Matrix::Zero(n, bins);
    b.count.assign(static_cast<std::size_t>(bins), 0);
    for (int r = 0; r < N; ++r) {
      // Bin k holds edges(k) <= z < edges(k + 1); the top edge belongs to the last bin.
      const double value = z(r, j);
      int k = static_cast<int>(std::upper_bound(b.edges.data() + 1, b.edges.data() + bins, value) - (b.edges.data() + 1));
      k = std::clamp(k, 0, bins - 1);
      ++b.count[static_cast<std::size_t>(k)];
      b.rms.col(k) += residual.row(r).cwiseAbs2().transpose();
    }
    for (int k = 0; k < bins; ++k)
      if (b.count[static_cast<std::size_t>(k)] > 0)
        b.rms.col(k) = (b.rms.col(k) / static_cast<double>(b.count[static_cast<std::size_t>(k)])).cwiseSqrt();
    out.push_back(std::move(b));
  }
  return out;
}

namespace {

/// sum over episodes of sum_t a(t) b(t - tau), for a, b de-meaned columns; rows in episode order.
double lagged_sum(const Vector& a, const Vector& b, const std::vector<int>& episode, int tau) {
  double sum = 0.0;
  const auto N = static_cast<int>(a.size());
  for (int t = 0; t < N; ++t) {
    const int s = t - tau;
    if (s < 0 || s >= N || episode[static_cast<std::size_t>(s)] != episode[static_cast<std::size_t>(t)]) continue;
    sum += a(t) * b(s);
  }
  return sum;
}

/// The within-episode autocorrelation at lags -max_lag..max_lag (whiteness.hpp's one-sided
/// autocorrelation, mirrored: rho(-k) = rho(k)).
Vector two_sided_autocorrelation(const Vector& a, const std::vector<int>& episode, int max_lag) {
  const Vector one_sided = autocorrelation(a, episode, max_lag);
  Vector out(2 * max_lag + 1);
  for (int k = 0; k <= max_lag; ++k) out(max_lag + k) = out(max_lag - k) = one_sided(k);
  return out;
}

}  // namespace

CrossCorrelation cross_correlation(const Transitions& data, const Matrix& residual, int max_lag) {
  const auto n = static_cast<int>(residual.cols());
  const auto m = static_cast<int>(data.u.cols());
  const auto N = static_cast<double>(residual.rows());
  CrossCorrelation out;
  out.max_lag = max_lag;
  out.values.assign(static_cast<std::size_t>(n), std::vector<Vector>(static_cast<std::size_t>(m)));
  out.band = Matrix::Zero(n, m);
  out.max_abs = Matrix::Zero(n, m);
  std::vector<Vector> u_centred, u_auto;
  for (int j = 0; j < m; ++j) {
    u_centred.push_back(data.u.col(j).array() - data.u.col(j).mean());
    u_auto.push_back(two_sided_autocorrelation(u_centred.back(), data.episode, max_lag));
  }
  for (int i = 0; i < n; ++i) {
    const Vector r = residual.col(i).array() - residual.col(i).mean();
    const Vector r_auto = two_sided_autocorrelation(r, data.episode, max_lag);
    for (int j = 0; j < m; ++j) {
      const double scale = std::sqrt(r.squaredNorm() * u_centred[static_cast<std::size_t>(j)].squaredNorm());
      Vector& values = out.values[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      values.resize(2 * max_lag + 1);
      for (int tau = -max_lag; tau <= max_lag; ++tau)
        values(tau + max_lag) = scale > 0.0 ? lagged_sum(r, u_centred[static_cast<std::size_t>(j)], data.episode, tau) / scale : 0.0;
      const double bartlett = std::max(0.0, r_auto.dot(u_auto[static_cast<std::size_t>(j)]));
      out.band(i, j) = 1.96 * std::sqrt(std::max(bartlett, 1.0) / N);
      out.max_abs(i, j) = values.cwiseAbs().maxCoeff();
    }
  }
  return out;
}

Matrix episode_rms(const Transitions& data, const Matrix& residual, int episodes) {
  Matrix sum = Matrix::Zero(episodes, residual.cols());
  Vector count = Vector::Zero(episodes);
  for (int r = 0; r < data.size(); ++r) {
    const int e = data.episode[static_cast<std::size_t>(r)];
    sum.row(e) += residual.row(r).cwiseAbs2();
    count(e) += 1.0;
  }
  for (int e = 0; e < episodes; ++e)
    if (count(e) > 0.0) sum.row(e) = (sum.row(e) / count(e)).cwiseSqrt();
  return sum;
}

}  // namespace gpilqg::diagnosis
