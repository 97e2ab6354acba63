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
};

/// Rolls `model` out from x0 under the controls u (m x T). `rng` must be non-null unless
/// noise == None. Throws std::invalid_argument when sizes do not match the model. Stops early and
/// returns false when a state becomes non-finite (a diverging rollout); the states reached so far
/// are kept and the rest are left as NaN-free copies of the last finite state, with `steps_completed`
/// telling how far it went.
struct RolloutResult {
  Trajectory trajectory;
  int steps_completed = 0;
  bool finite = true;
};

RolloutResult rollout(const StepModel& model, const VectorCRef& x0, const Matrix& u,
                      RolloutNoise noise = RolloutNoise::None, std::mt19937_64* rng = nullptr);

}  // namespace gpilqg
