#include "gpilqg/experiments/gp_ilqg_round.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/gp/noise_floor.hpp"

namespace gpilqg {

namespace {

/// The residual targets and the GP's noise floor are the simulator's step at the measured inputs,
/// states that carry the sensor noise. Where that step is not finite (the noise put a measured state
/// where the simulator diverges) there is nothing to learn; the culprit is the config's sensor noise,
/// `noise.observation` (of `gpilqg run` and `gpilqg plan` alike), named with its values.
void check_finite_at_measurements(const gp::ResidualData& all, const Matrix& noise_variance, const Vector& observation_std) {
  int bad = 0, first = -1;
  for (int r = 0; r < all.size(); ++r)
    if (!all.residuals.row(r).allFinite()) {
      if (first < 0) first = r;
      ++bad;
    }
  if (bad == 0 && noise_variance.allFinite()) return;
  const std::string where =
      bad > 0 ? fmt::format("the simulator's step is not finite at {} of {} measured inputs (the first: z = [{:.3g}])",
                            bad, all.size(), fmt::join(all.inputs.row(first), ", "))
              : "the simulator's Jacobian is not finite at the measured inputs";
  const bool noisy = observation_std.size() > 0 && (observation_std.array() > 0.0).any();
  throw InputError(fmt::format(
      "{}{}, so the GP's residual targets and noise floor are not finite; expected {}",
      noisy ? fmt::format("field 'noise.observation' = [{:g}]: ", fmt::join(observation_std, ", ")) : "", where,
      noisy ? "sensor noise small against the states, so that measured states stay where the simulator is finite"
            : "measurements where the simulator is finite"));
}

}  // namespace

GpRound plan_gp_ilqg_round(const DdpTask& task, const std::shared_ptr<const StepModel>& simulator,
                           const GpRoundInputs& in) {
  if (in.data == nullptr || in.backend == nullptr)
    throw std::invalid_argument("plan_gp_ilqg_round: data and backend are required");
  const int m = simulator->control_dim();
  if (in.previous_u_bar.size() && (in.previous_u_bar.rows() != m || in.previous_u_bar.cols() != task.horizon))
    throw std::invalid_argument("plan_gp_ilqg_round: the previous controls are not m x horizon");
  const TransitionData& data = *in.data;
  GpRound round;
  if (data.size() == 0) {
    round.plan = plan_with_ddp(task, simulator, DdpVariant::ILQG, in.previous_u_bar, in.plans_to_keep);
    return round;
  }
  const auto start = std::chrono::steady_clock::now();
  gp::ResidualData all = gp::make_residual_data(*simulator, data.x, data.u, data.x_next);
  gp::ResidualModelOptions options;
  options.fit = in.fit;
  options.threads = std::max(1, in.threads);
  Matrix noise_variance = gp::residual_noise_variance(*simulator, all, in.observation_std);
  check_finite_at_measurements(all, noise_variance, in.observation_std);
  if (in.known_noise) {
    // The known part is each transition's own; the learned part needs no floor of it.
    all.noise_variance = std::move(noise_variance);
    round.noise_floor = Vector::Zero(simulator->state_dim());
  } else {
    options.noise_floor = gp::least_noise_std(noise_variance);
    round.noise_floor = options.noise_floor;
  }
  const int newest = *std::max_element(data.iteration.begin(), data.iteration.end());
  std::vector<int> recent;
  for (int i = 0; i < data.size(); ++i)
    if (data.iteration[static_cast<std::size_t>(i)] == newest) recent.push_back(i);
  const gp::ResidualData validation = all.subset(recent);
  const gp::ResidualModel* previous = in.previous_model.get();
  auto model = std::make_shared<const gp::ResidualModel>(gp::ResidualModel::fit(
      simulator, all, *in.backend, options, nullptr, previous != nullptr ? &validation : nullptr, previous));
  round.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int D = static_cast<int>(all.inputs.cols());
  for (int i = 0; i < model->state_dim(); ++i) round.hyperparameters.push_back(model->output(i).parameters().head(D + 2));
  round.plan = plan_with_ddp(task, model, in.variant, in.previous_u_bar, in.plans_to_keep);
  return round;
}

}  // namespace gpilqg
