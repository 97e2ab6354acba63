#include "gpilqg/experiments/diagnosis/criteria/criterion.hpp"

#include <map>
#include <mutex>

#include "gpilqg/experiments/diagnosis/criteria/one_step.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"

namespace gpilqg::diagnosis {

namespace {

/// The state indices of the generalised velocities of `model`'s system (generalised_coordinates), or
/// every state when it has no generalised-force map. Built once per system.
const std::vector<int>& velocity_states(const ModelSpec& model) {
  static std::mutex guard;
  static std::map<std::string, std::vector<int>> known;
  const std::lock_guard<std::mutex> lock(guard);
  auto it = known.find(model.system);
  if (it != known.end()) return it->second;
  const DynamicsPtr dynamics = model.build();
  std::vector<int> states;
  for (const GeneralisedCoordinate& q : generalised_coordinates(*dynamics)) states.push_back(q.velocity);
  if (states.empty())
    for (int i = 0; i < dynamics->state_dim(); ++i) states.push_back(i);
  return known.emplace(model.system, std::move(states)).first->second;
}

}  // namespace

Matrix Criterion::predictions(const ModelSpec& model, const FitContext& c, int* diverged) const {
  return one_step_predictions(*make_step_model(model, c.integrator, c.dt, c.substeps), *c.data, diverged,
                              model.input_delay);
}

std::vector<int> Criterion::scale_channels(const FitContext& c) const { return velocity_states(c.model); }

double Criterion::own_change(const FitContext& c, int row, int channel) const {
  return c.data->x_next(row, channel) - c.residual(row, channel) - c.data->x(row, channel);
}

std::vector<std::string> Criterion::unidentifiable(const std::vector<LibraryEffect>&) const { return {}; }

std::shared_ptr<const Criterion> one_step_criterion() {
  static const auto shared = std::make_shared<const OneStepCriterion>();
  return shared;
}

double weighted_heldout_explained(const Transitions& data, const Matrix& residual, const Matrix& correction,
                                  const Vector& weights) {
  double before = 0.0, after = 0.0;
  for (int r : data.rows(true)) {
    before += residual.row(r).cwiseAbs2().dot(weights);
    after += (residual.row(r) - correction.row(r)).cwiseAbs2().dot(weights);
  }
  return before > 0.0 ? 1.0 - after / before : 0.0;
}

}  // namespace gpilqg::diagnosis
