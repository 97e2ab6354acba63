#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

#include <algorithm>
#include <stdexcept>


namespace gpilqg::diagnosis {

std::optional<FitCriterion> parse_fit_criterion(std::string_view name) {
  if (name == "one-step") return FitCriterion::OneStep;
  if (name == "simulation") return FitCriterion::Simulation;
  if (name == "inverse-dynamics") return FitCriterion::InverseDynamics;
  return std::nullopt;
}

std::string fit_criterion_name(FitCriterion criterion) {
  switch (criterion) {
    case FitCriterion::Simulation: return "simulation";
    case FitCriterion::InverseDynamics: return "inverse-dynamics";
    case FitCriterion::OneStep: break;
  }
  return "one-step";
}

std::vector<int> all_rows(const Transitions& data) {
  std::vector<int> rows(static_cast<std::size_t>(data.size()));
  for (int r = 0; r < data.size(); ++r) rows[static_cast<std::size_t>(r)] = r;
  return rows;
}

Matrix rows_of(const Matrix& y, const std::vector<int>& rows) {
  Matrix out(static_cast<Eigen::Index>(rows.size()), y.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = y.row(rows[i]);
  return out;
}

Matrix simulated_predictions(const StepModel& model, const Transitions& data, const Matrix& u,
                             const std::vector<int>& rows, int window, int* restarts) {
  if (window < 1) throw std::invalid_argument("simulated_predictions: the window must be >= 1 row");
  const int n = model.state_dim();
  Matrix out(static_cast<Eigen::Index>(rows.size()), n);
  Vector x(n), next(n);
  const auto workspace = model.make_workspace();
  int bad = 0;
  int previous = -2, episode_start = 0;
  bool restart_next = true;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int r = rows[k];
    const int episode = data.episode[static_cast<std::size_t>(r)];
    const bool new_episode = r == 0 || data.episode[static_cast<std::size_t>(r - 1)] != episode;
    if (new_episode) {
      episode_start = r;
    } else if (r != previous + 1) {
      // A gap in the row set: find where r's episode starts, so that r's window is the same as over all rows.
      episode_start = r;
      while (episode_start > 0 && data.episode[static_cast<std::size_t>(episode_start - 1)] == episode) --episode_start;
    }
    // Start of a window: the measured state. Inside: the simulated one.
    const bool window_start = (r - episode_start) % window == 0;
    if (window_start || r != previous + 1 || restart_next) x = data.x.row(r).transpose();
    restart_next = false;
    model.step(x, u.row(r).transpose(), next, nullptr, *workspace);
    if (prediction_diverged(next)) {
      ++bad;
      out.row(static_cast<Eigen::Index>(k)) = data.x.row(r);
      restart_next = true;  // the next row starts from its measured state
    } else {
      out.row(static_cast<Eigen::Index>(k)) = next.transpose();
      x = next;
    }
    previous = r;
  }
  if (restarts != nullptr) *restarts = bad;
  return out;
}

}  // namespace gpilqg::diagnosis
