#include "gpilqg/experiments/gp_ilqg_round.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "gpilqg/gp/noise_floor.hpp"

namespace gpilqg {

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
    round.plan = plan_with_ddp(task, simulator, DdpVariant::ILQG, in.previous_u_bar);
    return round;
  }
  const auto start = std::chrono::steady_clock::now();
  const gp::ResidualData all = gp::make_residual_data(*simulator, data.x, data.u, data.x_next);
  const int newest = *std::max_element(data.iteration.begin(), data.iteration.end());
  std::vector<int> recent;
  for (int i = 0; i < data.size(); ++i)
    if (data.iteration[static_cast<std::size_t>(i)] == newest) recent.push_back(i);
  const gp::ResidualData validation = all.subset(recent);
  const gp::ResidualModel* previous = in.previous_model.get();
  gp::ResidualModelOptions options;
  options.fit = in.fit;
  options.threads = std::max(1, in.threads);
  options.noise_floor = gp::sensor_noise_floor(*simulator, all, in.observation_std);
  round.noise_floor = options.noise_floor;
  auto model = std::make_shared<const gp::ResidualModel>(gp::ResidualModel::fit(
      simulator, all, *in.backend, options, nullptr, previous != nullptr ? &validation : nullptr, previous));
  round.fit_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int D = static_cast<int>(all.inputs.cols());
  for (int i = 0; i < model->state_dim(); ++i) round.hyperparameters.push_back(model->output(i).parameters().head(D + 2));
  round.plan = plan_with_ddp(task, model, in.variant, in.previous_u_bar);
  return round;
}

}  // namespace gpilqg
