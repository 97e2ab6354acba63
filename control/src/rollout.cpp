#include "gpilqg/control/rollout.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

bool sample_step(const StepModel& model, const VectorCRef& x, const VectorCRef& u, RolloutNoise noise,
                 DiffusionColumns& scratch, std::mt19937_64* rng, VectorRef x_next) {
  model.step(x, u, x_next);
  if (noise != RolloutNoise::None) {
    if (rng == nullptr) throw std::invalid_argument("sample_step: a random generator is needed to sample noise");
    std::normal_distribution<double> normal(0.0, 1.0);
    const double sqrt_dt = std::sqrt(model.dt());
    auto add_columns = [&] {
      for (int i = 0; i < scratch.count(); ++i) x_next += (sqrt_dt * normal(*rng)) * scratch.columns.col(i);
    };
    if (noise != RolloutNoise::UncertaintyOnly) {
      model.noise(x, u, scratch, false);
      add_columns();
    }
    if (noise == RolloutNoise::ProcessAndUncertainty || noise == RolloutNoise::UncertaintyOnly) {
      model.uncertainty(x, u, scratch, false);
      add_columns();
    }
  }
  return x_next.allFinite();
}

void add_observation_noise(const Vector& std, std::mt19937_64& rng, VectorRef x) {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (Eigen::Index i = 0; i < std.size(); ++i) x(i) += std(i) * normal(rng);
}

RolloutResult rollout(const StepModel& model, const VectorCRef& x0, const Matrix& u, RolloutNoise noise,
                      std::mt19937_64* rng) {
  const int n = model.state_dim();
  const int m = model.control_dim();
  if (x0.size() != n)
    throw std::invalid_argument("rollout: x0 has " + std::to_string(x0.size()) + " entries; expected " +
                                std::to_string(n));
  if (u.rows() != m)
    throw std::invalid_argument("rollout: controls have " + std::to_string(u.rows()) +
                                " rows; expected " + std::to_string(m));
  if (noise != RolloutNoise::None && rng == nullptr)
    throw std::invalid_argument("rollout: a random generator is needed to sample noise");

  const int T = static_cast<int>(u.cols());
  RolloutResult result;
  result.trajectory = Trajectory(n, m, T);
  result.trajectory.u = u;
  result.trajectory.x.col(0) = x0;
  DiffusionColumns terms;
  Vector next(n);
  for (int t = 0; t < T; ++t) {
    const auto x = result.trajectory.x.col(t);
    if (!sample_step(model, x, u.col(t), noise, terms, rng, next)) {
      result.finite = false;
      for (int s = t + 1; s <= T; ++s) result.trajectory.x.col(s) = x;
      return result;
    }
    result.trajectory.x.col(t + 1) = next;
    result.steps_completed = t + 1;
  }
  return result;
}

}  // namespace gpilqg
