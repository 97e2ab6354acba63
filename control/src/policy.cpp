#include "gpilqg/control/policy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

void AffinePolicy::control(int t, const VectorCRef& x, VectorRef u, double alpha) const {
  thread_local Vector dx;  // no allocation per call once sized
  dx = x - x_bar.col(t);
  u = u_bar.col(t);
  u.noalias() += alpha * k.col(t);
  u.noalias() += K[static_cast<std::size_t>(t)] * dx;
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
  const int n = world.state_dim(), m = world.control_dim(), T = policy.horizon();
  if (x0.size() != n)
    throw std::invalid_argument("policy rollout: x0 has " + std::to_string(x0.size()) + " entries; expected " +
                                std::to_string(n));
  if (policy.u_bar.rows() != m || policy.x_bar.rows() != n)
    throw std::invalid_argument("policy rollout: the policy does not fit the world's dimensions");
  if (settings.observation_std.size() != 0 && settings.observation_std.size() != n)
    throw std::invalid_argument("policy rollout: observation_std has " +
                                std::to_string(settings.observation_std.size()) + " entries; expected " +
                                std::to_string(n));
  PolicyRollout out;
  out.trajectory = Trajectory(n, m, T);
  out.trajectory.x.col(0) = x0;
  Vector observed(n), next(n);
  DiffusionColumns columns;
  for (int t = 0; t < T; ++t) {
    const auto x = out.trajectory.x.col(t);
    observed = x;
    add_observation_noise(settings.observation_std, rng, observed);
    auto u = out.trajectory.u.col(t);
    policy.control(t, observed, u);
    if (!sample_step(world, x, u, settings.noise(), columns, &rng, next)) {
      out.finite = false;
      for (int s = t + 1; s <= T; ++s) out.trajectory.x.col(s) = x;
      return out;
    }
    out.trajectory.x.col(t + 1) = next;
    out.steps_completed = t + 1;
  }
  return out;
}

}  // namespace gpilqg
