#include "gpilqg/control/rollout.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

std::string_view to_string(RolloutStatus status) {
  switch (status) {
    case RolloutStatus::Completed: return "completed";
    case RolloutStatus::StateBoundExceeded: return "state_bound_exceeded";
    case RolloutStatus::NonFiniteState: return "non_finite_state";
    case RolloutStatus::NonFiniteControl: return "non_finite_control";
  }
  return "unknown";
}

RolloutStatus check_divergence(const VectorCRef& x, double max_magnitude) {
  if (!x.allFinite()) return RolloutStatus::NonFiniteState;
  if (x.size() > 0 && x.cwiseAbs().maxCoeff() > max_magnitude) return RolloutStatus::StateBoundExceeded;
  return RolloutStatus::Completed;
}

bool sample_step(const StepModel& model, const VectorCRef& x, const VectorCRef& u, RolloutNoise noise,
                 DiffusionColumns& scratch, std::mt19937_64* rng, VectorRef x_next, StepWorkspace& workspace) {
  model.step(x, u, x_next, nullptr, workspace);
  if (noise != RolloutNoise::None) {
    if (rng == nullptr) throw std::invalid_argument("sample_step: a random generator is needed to sample noise");
    std::normal_distribution<double> normal(0.0, 1.0);
    const double sqrt_dt = std::sqrt(model.dt());
    auto add_columns = [&] {
      for (int i = 0; i < scratch.count(); ++i) x_next += (sqrt_dt * normal(*rng)) * scratch.columns.col(i);
    };
    if (noise != RolloutNoise::UncertaintyOnly) {
      model.noise(x, u, scratch, false, workspace);
      add_columns();
    }
    if (noise == RolloutNoise::ProcessAndUncertainty || noise == RolloutNoise::UncertaintyOnly) {
      model.uncertainty(x, u, scratch, false, workspace);
      add_columns();
    }
  }
  return x_next.allFinite();
}

void add_observation_noise(const Vector& std, std::mt19937_64& rng, VectorRef x) {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::Index i = 0; i < std.size(); ++i) x(i) += std(i) * normal(rng);
}

RolloutResult closed_loop_rollout(const StepModel& world, const VectorCRef& x0, int steps,
                                  const Controller& controller, RolloutNoise noise,
                                  const Vector& observation_std, std::mt19937_64* rng,
                                  double max_state_magnitude) {
  const int n = world.state_dim();
  const int m = world.control_dim();
  if (x0.size() != n)
    throw std::invalid_argument("rollout: x0 has " + std::to_string(x0.size()) + " entries; expected " +
                                std::to_string(n));
  if (!x0.allFinite()) throw std::invalid_argument("rollout: x0 has non-finite entries; expected a finite state");
  if (!(max_state_magnitude > 0.0))
    throw std::invalid_argument("rollout: max_state_magnitude = " + std::to_string(max_state_magnitude) +
                                "; expected > 0");
  if (steps < 0) throw std::invalid_argument("rollout: steps = " + std::to_string(steps) + "; expected >= 0");
  if (observation_std.size() != 0 && observation_std.size() != n)
    throw std::invalid_argument("rollout: observation_std has " + std::to_string(observation_std.size()) +
                                " entries; expected " + std::to_string(n));
  if ((noise != RolloutNoise::None || observation_std.size() != 0) && rng == nullptr)
    throw std::invalid_argument("rollout: a random generator is needed to sample noise");

  RolloutResult result;
  result.trajectory = Trajectory(n, m, steps);
  result.trajectory.x.col(0) = x0;
  DiffusionColumns scratch;
  const auto workspace = world.make_workspace();
  Vector observed(n), next(n);
  for (int t = 0; t < steps; ++t) {
    const auto x = result.trajectory.x.col(t);
    observed = x;
    if (observation_std.size() != 0) add_observation_noise(observation_std, *rng, observed);
    auto u = result.trajectory.u.col(t);
    controller(t, observed, u);
    RolloutStatus status = u.allFinite() ? RolloutStatus::Completed : RolloutStatus::NonFiniteControl;
    if (status == RolloutStatus::Completed) {
      sample_step(world, x, u, noise, scratch, rng, next, *workspace);
      status = check_divergence(next, max_state_magnitude);
    }
    if (status != RolloutStatus::Completed) {
      // Diverged: stop, keep the result free of NaN and inf (the last state within the bound
      // repeated, controls not applied zero) and say why.
      result.finite = false;
      result.status = status;
      if (status == RolloutStatus::NonFiniteControl) u.setZero();
      for (int s = t + 1; s <= steps; ++s) result.trajectory.x.col(s) = x;
      return result;
    }
    result.trajectory.x.col(t + 1) = next;
    result.steps_completed = t + 1;
  }
  return result;
}

RolloutResult rollout(const StepModel& model, const VectorCRef& x0, const Matrix& u, RolloutNoise noise,
                      std::mt19937_64* rng) {
  if (u.rows() != model.control_dim())
    throw std::invalid_argument("rollout: controls have " + std::to_string(u.rows()) + " rows; expected " +
                                std::to_string(model.control_dim()));
  const Controller open_loop = [&u](int t, const VectorCRef&, VectorRef out) { out = u.col(t); };
  return closed_loop_rollout(model, x0, static_cast<int>(u.cols()), open_loop, noise, Vector(), rng);
}

}  // namespace gpilqg
