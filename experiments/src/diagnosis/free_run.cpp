#include "gpilqg/experiments/diagnosis/free_run.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

Matrix measured_controls(const MatrixCRef& measured) { return measured; }

FreeRunTrajectory free_run(const FreeRunModel& model, const Episode& episode) {
  const StepModel& phi = *model.step;
  const int n = phi.state_dim();
  const Eigen::Index T = episode.x.rows();
  if (episode.x.cols() != n || episode.u.cols() != phi.control_dim() || episode.u.rows() != T || T < 1)
    throw std::invalid_argument(fmt::format("free run of '{}': episode {} has {} x {} states and {} x {} controls; the model "
                                            "has {} states and {} controls", model.name, episode.id, T, episode.x.cols(),
                                            episode.u.rows(), episode.u.cols(), n, phi.control_dim()));
  const Matrix u = (model.controls ? model.controls : ControlSource(measured_controls))(episode.u);
  if (u.rows() != episode.u.rows() || u.cols() != episode.u.cols())
    throw std::invalid_argument(fmt::format("free run of '{}': the control source returned {} x {} controls for {} x {}",
                                            model.name, u.rows(), u.cols(), episode.u.rows(), episode.u.cols()));

  // The project's one rollout loop (control/rollout.hpp): it stops at the first diverged state.
  FreeRunTrajectory out;
  out.model = model.name;
  const RolloutResult run = rollout(phi, episode.x.row(0).transpose(), u.topRows(T - 1).transpose());
  out.steps = run.steps_completed;
  out.diverged = !run.finite;
  out.predicted = run.trajectory.x.leftCols(out.steps + 1).transpose();
  out.fit_percent = Vector::Zero(n);
  if (out.steps > 0)
    for (int i = 0; i < n; ++i)
      out.fit_percent(i) = fit_percent(episode.x.col(i).segment(1, out.steps), out.predicted.col(i).tail(out.steps));
  return out;
}

std::vector<FreeRunEpisode> free_run(const MeasurementSet& set, const std::vector<int>& episodes,
                                     const std::vector<FreeRunModel>& models) {
  std::vector<FreeRunEpisode> out;
  for (int index : episodes) {
    const Episode& e = set.episodes.at(static_cast<std::size_t>(index));
    if (e.length() < 2) continue;
    FreeRunEpisode run;
    run.index = index;
    run.id = e.id;
    run.t = e.t;
    run.measured = e.x;
    for (const FreeRunModel& model : models) run.models.push_back(free_run(model, e));
    out.push_back(std::move(run));
  }
  return out;
}

}  // namespace gpilqg::diagnosis
