#include "gpilqg/experiments/diagnosis/criteria/simulation.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"

namespace gpilqg::diagnosis {

SimulationCriterion::SimulationCriterion(int window, std::shared_ptr<const InitialStateSensitivity> starts)
    : window_(window), starts_(std::move(starts)) {
  if (window < 1) throw std::invalid_argument("the simulation criterion needs windows of at least 1 row");
  // Sensitivities of other windows do not describe these windows' starts.
  if (starts_ && starts_->window != window_) starts_ = nullptr;
}

Matrix SimulationCriterion::predictions(const ModelSpec& model, const FitContext& c, int* diverged) const {
  return simulated_predictions(*make_step_model(model, c.integrator, c.dt, c.substeps), *c.data,
                               applied_controls(*c.data, model.input_delay), all_rows(*c.data), window_, diverged);
}

Matrix SimulationCriterion::residual(const ModelSpec& model, const FitContext& c, int* diverged) const {
  const Matrix errors = c.data->x_next - predictions(model, c, diverged);
  if (!starts_) return errors;
  return without_start_error(*starts_, all_rows(*c.data), errors, c.weights);
}

Vector SimulationCriterion::weighted_residual(const ModelSpec& model, const FitContext& c, const std::vector<int>& rows,
                                              bool* finite) const {
  const auto n = static_cast<Eigen::Index>(c.weights.size());
  const Vector sqrt_w = c.weights.cwiseSqrt();
  int restarts = 0;
  const Matrix predicted = simulated_predictions(*make_step_model(model, c.integrator, c.dt, c.substeps), *c.data,
                                                 applied_controls(*c.data, model.input_delay), rows, window_, &restarts);
  if (restarts > 0 && finite != nullptr) *finite = false;
  Vector out(static_cast<Eigen::Index>(rows.size()) * n);
  for (std::size_t k = 0; k < rows.size(); ++k)
    out.segment(static_cast<Eigen::Index>(k) * n, n) =
        sqrt_w.cwiseProduct((c.data->x_next.row(rows[k]) - predicted.row(static_cast<Eigen::Index>(k))).transpose());
  if (starts_) remove_start_error(*starts_, rows, out);
  return out;
}

double SimulationCriterion::flexible_share(const ModelSpec& model, const OneStepGp* gp, const FitContext& c,
                                           const GpSettings&) const {
  const Transitions& data = *c.data;
  const std::vector<int> rows = data.rows(true);
  const Matrix u = applied_controls(data, model.input_delay);
  const Matrix plain =
      simulated_predictions(*make_step_model(model, c.integrator, c.dt, c.substeps), data, u, rows, window_);
  const Matrix flexible = simulated_predictions(*gp->gp.model, data, u, rows, window_);
  Matrix measured(static_cast<Eigen::Index>(rows.size()), data.x_next.cols());
  for (std::size_t k = 0; k < rows.size(); ++k) measured.row(static_cast<Eigen::Index>(k)) = data.x_next.row(rows[k]);
  Matrix plain_errors = measured - plain, flexible_errors = measured - flexible;
  if (starts_) {
    plain_errors = without_start_error(*starts_, rows, plain_errors, c.weights);
    flexible_errors = without_start_error(*starts_, rows, flexible_errors, c.weights);
  }
  double before = 0.0, after = 0.0;
  for (Eigen::Index k = 0; k < measured.rows(); ++k) {
    before += plain_errors.row(k).cwiseAbs2().dot(c.weights);
    after += flexible_errors.row(k).cwiseAbs2().dot(c.weights);
  }
  return before > 0.0 ? 1.0 - after / before : 0.0;
}

std::string SimulationCriterion::scored_on() const {
  return fmt::format("the simulation error over windows of {} samples", window_);
}

std::string SimulationCriterion::description(double dt, int restarts) const {
  return fmt::format("criterion: simulation error over windows of {} samples ({:g} s), each window's start {}{}", window_,
                     window_ * dt, starts_ ? "estimated" : "measured",
                     restarts > 0 ? fmt::format(", {} restarts after a diverged state", restarts) : "");
}

}  // namespace gpilqg::diagnosis
