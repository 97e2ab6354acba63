#include "gpilqg/experiments/diagnosis/initial_state.hpp"

#include <cmath>

#include <Eigen/QR>

#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

namespace gpilqg::diagnosis {

namespace {

/// The window index of every row: windows of `window` rows from each episode's first row, numbered
/// in row order (the windows of simulated_predictions over all rows).
std::vector<int> window_indices(const Transitions& data, int window) {
  std::vector<int> out(static_cast<std::size_t>(data.size()));
  int index = -1, episode_start = 0;
  for (int r = 0; r < data.size(); ++r) {
    const bool new_episode = r == 0 || data.episode[static_cast<std::size_t>(r - 1)] != data.episode[static_cast<std::size_t>(r)];
    if (new_episode) episode_start = r;
    if ((r - episode_start) % window == 0) ++index;
    out[static_cast<std::size_t>(r)] = index;
  }
  return out;
}

}  // namespace

InitialStateSensitivity initial_state_sensitivity(const StepModel& model, const Transitions& data, const Matrix& u,
                                                  int window, const Vector& weights) {
  const auto n = static_cast<Eigen::Index>(data.x.cols());
  const auto N = static_cast<Eigen::Index>(data.size());
  InitialStateSensitivity out;
  out.window = window;
  out.window_of_row = window_indices(data, window);
  out.weighted = Matrix::Zero(N * n, n);
  const std::vector<int> rows = all_rows(data);
  const Vector sqrt_w = weights.cwiseSqrt();
  std::vector<bool> usable(out.window_of_row.empty() ? 0 : static_cast<std::size_t>(out.window_of_row.back()) + 1, true);
  Transitions shifted = data;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double rms = N > 0 ? std::sqrt(data.x.col(j).squaredNorm() / static_cast<double>(N)) : 0.0;
    const double h = 1e-6 * (1.0 + rms);
    // Every row's measured state shifted: simulated_predictions reads x only at the windows' starts.
    // A diverged prediction comes back as the (shifted) measured state, which no simulated state equals
    // exactly: its window's difference is no derivative.
    const auto shifted_run = [&](double step, Matrix& predicted) {
      shifted.x.col(j) = data.x.col(j).array() + step;
      int restarts = 0;
      predicted = simulated_predictions(model, shifted, u, rows, window, &restarts);
      if (restarts > 0)
        for (Eigen::Index r = 0; r < N; ++r)
          if (predicted.row(r) == shifted.x.row(r))
            usable[static_cast<std::size_t>(out.window_of_row[static_cast<std::size_t>(r)])] = false;
    };
    Matrix up, down;
    shifted_run(h, up);
    shifted_run(-h, down);
    shifted.x.col(j) = data.x.col(j);
    for (Eigen::Index r = 0; r < N; ++r) {
      const Vector d = sqrt_w.cwiseProduct((up.row(r) - down.row(r)).transpose()) / (2.0 * h);
      if (!d.allFinite()) usable[static_cast<std::size_t>(out.window_of_row[static_cast<std::size_t>(r)])] = false;
      out.weighted.block(r * n, j, n, 1) = d;
    }
  }
  for (Eigen::Index r = 0; r < N; ++r)
    if (!usable[static_cast<std::size_t>(out.window_of_row[static_cast<std::size_t>(r)])]) out.weighted.middleRows(r * n, n).setZero();
  return out;
}

void remove_start_error(const InitialStateSensitivity& sensitivity, const std::vector<int>& rows, Vector& weighted) {
  const auto n = sensitivity.weighted.cols();
  std::size_t k = 0;
  while (k < rows.size()) {
    // The block: consecutive rows of one window.
    std::size_t end = k + 1;
    const int w = sensitivity.window_of_row[static_cast<std::size_t>(rows[k])];
    while (end < rows.size() && rows[end] == rows[end - 1] + 1 &&
           sensitivity.window_of_row[static_cast<std::size_t>(rows[end])] == w)
      ++end;
    const auto m = static_cast<Eigen::Index>(end - k) * n;
    Matrix S(m, n);
    for (std::size_t i = k; i < end; ++i)
      S.middleRows(static_cast<Eigen::Index>(i - k) * n, n) = sensitivity.weighted.middleRows(rows[i] * n, n);
    if (m > n && !S.isZero(0.0)) {
      const Eigen::ColPivHouseholderQR<Matrix> qr(S);
      const Eigen::Index rank = qr.rank();
      if (rank > 0) {
        auto block = weighted.segment(static_cast<Eigen::Index>(k) * n, m);
        // (I - P) e: apply Q', zero the first `rank` coordinates, apply Q.
        Vector coordinates = qr.householderQ().adjoint() * block;
        coordinates.head(rank).setZero();
        block = qr.householderQ() * coordinates;
      }
    }
    k = end;
  }
}

Matrix without_start_error(const InitialStateSensitivity& sensitivity, const std::vector<int>& rows, const Matrix& errors,
                           const Vector& weights) {
  const auto n = errors.cols();
  const Vector sqrt_w = weights.cwiseSqrt();
  Vector stacked(errors.rows() * n);
  for (Eigen::Index k = 0; k < errors.rows(); ++k) stacked.segment(k * n, n) = sqrt_w.cwiseProduct(errors.row(k).transpose());
  remove_start_error(sensitivity, rows, stacked);
  Matrix out(errors.rows(), n);
  for (Eigen::Index k = 0; k < errors.rows(); ++k) out.row(k) = stacked.segment(k * n, n).cwiseQuotient(sqrt_w).transpose();
  return out;
}

}  // namespace gpilqg::diagnosis
