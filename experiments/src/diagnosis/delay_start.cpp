#include "gpilqg/experiments/diagnosis/delay_start.hpp"

#include <cmath>

namespace gpilqg::diagnosis {

int input_delay_start(const FitContext& c, int max_lag) {
  const Transitions& data = *c.data;
  const int N = data.size();
  const auto n = static_cast<Eigen::Index>(data.x.cols());
  if (N == 0) return 0;
  const std::vector<int> training = data.rows(false);
  // The states' weights: the context's under a state criterion; under inverse dynamics (whose weights
  // are the force components') the inverse variance of each state's measured one-step change.
  Vector weights = c.weights;
  if (weights.size() != n) {
    weights = Vector::Ones(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int r : training) sum += std::pow(data.x_next(r, i) - data.x(r, i), 2);
      const double variance = sum / std::max<double>(1.0, static_cast<double>(training.size()));
      if (variance > 0.0) weights(i) = 1.0 / variance;
    }
  }
  Vector u_ref = Vector::Zero(data.u.cols());
  for (int r : training) u_ref += data.u.row(r).transpose();
  u_ref /= static_cast<double>(std::max<std::size_t>(1, training.size()));

  // Weighted responses at every row (rows of held-out episodes are not used below).
  const auto model = make_step_model(c.model, c.integrator, c.dt, c.substeps);
  const auto workspace = model->make_workspace();
  const Vector sqrt_w = weights.cwiseSqrt();
  Matrix measured(N, n), predicted(N, n);
  Vector with_u(n), with_ref(n);
  for (int r = 0; r < N; ++r) {
    model->step(data.x.row(r).transpose(), u_ref, with_ref, nullptr, *workspace);
    model->step(data.x.row(r).transpose(), data.u.row(r).transpose(), with_u, nullptr, *workspace);
    if (prediction_diverged(with_ref) || prediction_diverged(with_u)) {
      measured.row(r).setZero();
      predicted.row(r).setZero();
      continue;
    }
    measured.row(r) = sqrt_w.cwiseProduct(data.x_next.row(r).transpose() - with_ref).transpose();
    predicted.row(r) = sqrt_w.cwiseProduct(with_u - with_ref).transpose();
  }
  int best_lag = 0;
  double best = 0.0;
  for (int lag = 0; lag <= max_lag; ++lag) {
    double cross = 0.0, mm = 0.0, pp = 0.0;
    for (int r : training) {
      const int s = r - lag;
      if (s < 0 || data.episode[static_cast<std::size_t>(s)] != data.episode[static_cast<std::size_t>(r)]) continue;
      cross += measured.row(r).dot(predicted.row(s));
      mm += measured.row(r).squaredNorm();
      pp += predicted.row(s).squaredNorm();
    }
    const double rho = mm > 0.0 && pp > 0.0 ? cross / std::sqrt(mm * pp) : 0.0;
    if (rho > best) {
      best = rho;
      best_lag = lag;
    }
  }
  return best_lag;
}

}  // namespace gpilqg::diagnosis
