#include "gpilqg/control/rollout.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

namespace {

/// Adds sqrt(dt) * columns * xi with fresh standard normal draws.
void add_sampled(const DiffusionColumns& terms, double sqrt_dt, std::mt19937_64& rng, VectorRef x) {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < terms.count(); ++i) x += (sqrt_dt * normal(rng)) * terms.columns.col(i);
}

}  // namespace

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
  const double sqrt_dt = std::sqrt(model.dt());
  DiffusionColumns terms;
  Vector next(n);
  for (int t = 0; t < T; ++t) {
    const auto x = result.trajectory.x.col(t);
    model.step(x, u.col(t), next);
    if (noise != RolloutNoise::None) {
      model.noise(x, u.col(t), terms, false);
      add_sampled(terms, sqrt_dt, *rng, next);
      if (noise == RolloutNoise::ProcessAndUncertainty) {
        model.uncertainty(x, u.col(t), terms, false);
        add_sampled(terms, sqrt_dt, *rng, next);
      }
    }
    if (!next.allFinite()) {
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
