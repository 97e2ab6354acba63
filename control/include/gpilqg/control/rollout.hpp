#pragma once
/// @file rollout.hpp
/// Simulating a step model forwards under a control sequence, with or without sampled noise.
///
/// With noise, each step draws xi ~ N(0, I_p) and xi_G ~ N(0, I_q) and applies the paper's
///   x' = phi(x, u) + F(x, u) xi sqrt(dt) + G(x, u) xi_G sqrt(dt).

#include <random>

#include "gpilqg/control/trajectory.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

/// What to sample during a rollout.
enum class RolloutNoise {
  None,                    ///< the mean step only
  Process,                 ///< process noise F
  ProcessAndUncertainty,   ///< F and the model-uncertainty columns G
  UncertaintyOnly,         ///< the model-uncertainty columns G alone
};

/// Rolls `model` out from x0 under the controls u (m x T). `rng` must be non-null unless
/// noise == None. Throws std::invalid_argument when sizes do not match the model. When a state becomes
/// non-finite (a diverging rollout) it stops with finite = false: the states reached so far are kept,
/// the remaining columns repeat the last finite state (so no NaN is ever returned), and
/// `steps_completed` tells how far it went.
struct RolloutResult {
  Trajectory trajectory;
  int steps_completed = 0;
  bool finite = true;
};

RolloutResult rollout(const StepModel& model, const VectorCRef& x0, const Matrix& u,
                      RolloutNoise noise = RolloutNoise::None, std::mt19937_64* rng = nullptr);

/// One sampled step, the shared mechanism of every simulated rollout in the project:
///   x' = phi(x, u) [+ sqrt(dt) F(x, u) xi] [+ sqrt(dt) G(x, u) xi_G]
/// as `noise` selects (None: the mean step; rng may then be null). `scratch` holds the columns
/// between calls. Returns false when x' is not finite (a diverging rollout).
bool sample_step(const StepModel& model, const VectorCRef& x, const VectorCRef& u, RolloutNoise noise,
                 DiffusionColumns& scratch, std::mt19937_64* rng, VectorRef x_next);

/// Adds N(0, diag(std^2)) to x (a measurement of the state); no-op when `std` is empty.
void add_observation_noise(const Vector& std, std::mt19937_64& rng, VectorRef x);

}  // namespace gpilqg
