#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "gpilqg/experiments/diagnosis/accelerations.hpp"
#include "gpilqg/experiments/diagnosis/derivative_window.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/initial_state.hpp"

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

namespace {

/// Inverse dynamics: the accelerations, the generalised-force residual, its weights and the model's
/// own force (inverse_dynamics_context in simulation_error.hpp).
FitContext inverse_dynamics_context(FitContext context) {
  context.window = 1;
  context.criterion = FitCriterion::InverseDynamics;
  if (context.data == nullptr) return context;
  const Transitions& data = *context.data;
  const DynamicsPtr system = context.model.build();
  const ForceComponents components = force_components(*system);
  const auto k = static_cast<Eigen::Index>(components.forces.size());
  const AccelerationEstimate estimate = estimate_accelerations(data, components.velocity_states(), context.dt);
  context.accelerations = std::make_shared<const Matrix>(estimate.qdd);
  context.acceleration_reach = estimate.window / 2;
  // Parallel filtering: the controls seen through the acceleration estimate's weights (accelerations.hpp).
  context.acceleration_window = estimate.window;
  context.filtered_delay = context.model.input_delay;
  context.filtered_controls = nullptr;
  context.filtered_controls = std::make_shared<const Matrix>(force_controls(context.model, context));
  const std::vector<int> rows = all_rows(data);
  context.residual =
      generalised_force_residual(context.model, data, *context.filtered_controls, *context.accelerations, rows);
  // The model's own force: the residual at zero acceleration is -W_v^-1 f_v.
  context.own_force = std::make_shared<const Matrix>(
      -generalised_force_residual(context.model, data, *context.filtered_controls, Matrix::Zero(data.size(), k), rows));
  // w_i = 1 / sigma_i^2 with sigma_i the white noise of component i's residual, from its repeated
  // differences within each record (difference_noise_std): the noise of the torque and of the
  // acceleration estimate, which a smooth missing force does not raise. Taken from the residual with
  // the controls as measured: the filter turns their white noise into a smooth one that differences
  // no longer see, and it scales every component's noise variance by the same |m|^2, so the weights'
  // ratios, which are all a fit uses, are those of the unfiltered noise.
  const Matrix unfiltered = generalised_force_residual(context.model, data, applied_controls(data, context.model.input_delay),
                                                       *context.accelerations, rows);
  const std::vector<RowSegment> segments = row_segments(data);
  context.weights.resize(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    std::vector<Vector> pieces;
    for (const RowSegment& s : segments) pieces.push_back(unfiltered.col(i).segment(s.first, s.end - s.first));
    const double rms = std::sqrt(unfiltered.col(i).squaredNorm() / std::max<double>(1.0, data.size()));
    const double sigma = std::max(difference_noise_std(pieces), 1e-12 * (1.0 + rms));
    context.weights(i) = 1.0 / (sigma * sigma);
  }
  return context;
}

}  // namespace

FitContext criterion_context(FitContext context, FitCriterion criterion, int window, int* restarts) {
  if (window < 1) throw std::invalid_argument("criterion_context: the window must be >= 1 row");
  if (restarts != nullptr) *restarts = 0;
  context.initial_state = nullptr;  // set below for the simulation criterion
  context.acceleration_window = 0;   // set by inverse_dynamics_context
  context.filtered_controls = nullptr;
  if (criterion == FitCriterion::InverseDynamics) return inverse_dynamics_context(std::move(context));
  if (criterion == FitCriterion::OneStep) {
    context.window = 1;
    context.criterion = FitCriterion::OneStep;
    return context;
  }
  context.criterion = FitCriterion::Simulation;
  context.window = window;
  // Held-out batches are whole windows (heldout_batch_length in effect_fit.cpp): the errors within a
  // window are strongly correlated.
  int bad = 0;
  if (context.data != nullptr) {
    const Transitions& data = *context.data;
    if (context.estimate_starts)
      context.initial_state = std::make_shared<const InitialStateSensitivity>(initial_state_sensitivity(
          *make_step_model(context.model, context.integrator, context.dt, context.substeps), data,
          applied_controls(data, context.model.input_delay), window, context.weights));
    context.residual = criterion_residual(context.model, context, &bad);
  }
  if (restarts != nullptr) *restarts = bad;
  return context;
}

}  // namespace gpilqg::diagnosis
