#include "gpilqg/control/policy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

void AffinePolicy::control(int t, const VectorCRef& x, VectorRef u, double alpha) const {
  // u = u_bar + alpha k + K (x - x_bar), column by column: no temporary, nothing allocated.
  u = u_bar.col(t);
  u.noalias() += alpha * k.col(t);
  const Matrix& gain = K[static_cast<std::size_t>(t)];
  for (Eigen::Index j = 0; j < gain.cols(); ++j) u.noalias() += (x(j) - x_bar(j, t)) * gain.col(j);
  if (u_min.size()) u = u.cwiseMax(u_min);
  if (u_max.size()) u = u.cwiseMin(u_max);
}

double AffinePolicy::distance(const AffinePolicy& other) const {
  if (other.horizon() != horizon() || other.u_bar.rows() != u_bar.rows())
    throw std::invalid_argument("policy distance: the policies have different shapes");
  double d = ((u_bar + k) - (other.u_bar + other.k)).cwiseAbs().maxCoeff();
  for (std::size_t t = 0; t < K.size(); ++t) d = std::max(d, (K[t] - other.K[t]).cwiseAbs().maxCoeff());
  return d;
}

RolloutNoise PolicyRolloutSettings::noise() const {
  if (uncertainty) return process_noise ? RolloutNoise::ProcessAndUncertainty : RolloutNoise::UncertaintyOnly;
  return process_noise ? RolloutNoise::Process : RolloutNoise::None;
}

PolicyRollout rollout_policy(const StepModel& world, const AffinePolicy& policy, const VectorCRef& x0,
                             const PolicyRolloutSettings& settings, std::mt19937_64& rng) {
  if (policy.u_bar.rows() != world.control_dim() || policy.x_bar.rows() != world.state_dim())
    throw std::invalid_argument("policy rollout: the policy does not fit the world's dimensions");
  const Controller feedback = [&policy](int t, const VectorCRef& observed, VectorRef u) {
    policy.control(t, observed, u);
  };
  return closed_loop_rollout(world, x0, policy.horizon(), feedback, settings.noise(), settings.observation_std, &rng);
}

Matrix closed_loop_controls(const StepModel& model, const AffinePolicy& policy, const VectorCRef& x0) {
  PolicyRolloutSettings mean_step;
  mean_step.process_noise = false;
  std::mt19937_64 unused;  // no noise is drawn
  return rollout_policy(model, policy, x0, mean_step, unused).trajectory.u;
}

}  // namespace gpilqg
