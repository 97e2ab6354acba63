#pragma once
/// @file warm_start.hpp
/// Where a DDP solve on a changed model starts from a policy planned on the previous model (the
/// previous round of Algorithm 1: the same task, a refitted GP).
///
/// The previous nominal controls u_bar, replayed open loop on the new model, drift away from x_bar
/// wherever the models differ, and on an unstable system (a quadrotor, a pendulum) the drift
/// compounds over the horizon: the quadrotor's refitted GP turned an optimum of cost 3.5 into an
/// initial trajectory of cost 1e4 to 4e5 that had fallen out of the sky, and DDP from there stalled or
/// found a different, poor plan. The previous policy in closed loop keeps the rollout near x_bar:
///
///   x_0 = x0,   u_t = clamp(u_bar_t + k_t + K_t (x_t - x_bar_t)),   x_{t+1} = phi_new(x_t, u_t),
///
/// noise-free (the mean step), so that replaying the controls u_t open loop on the same model
/// reproduces this trajectory exactly: those controls are the warm start.

#include "gpilqg/control/policy.hpp"
#include "gpilqg/core/cost.hpp"

namespace gpilqg {

/// Which start warm_start_controls chose.
enum class WarmStart {
  ClosedLoop,  ///< the previous policy's controls along its closed-loop rollout on the new model
  OpenLoop,    ///< the previous nominal controls u_bar (the closed loop cost more, or diverged)
};

struct WarmStartControls {
  Matrix controls;         ///< m x T, within the policy's limits
  WarmStart kind = WarmStart::ClosedLoop;
  double cost = 0.0;       ///< l_T(x_T) + sum_t l_t(x_t, u_t) of the chosen start on the model
  double other_cost = 0.0; ///< the same of the start not chosen (+infinity when its rollout diverged)
};

/// The controls to start DDP from on `model`, given the `previous` policy (see the file comment):
/// the closed-loop controls, or u_bar open loop when that costs less on `model` (the previous
/// policy's feedback can make things worse when the model changed a lot), by the nominal cost
/// under `cost`. A diverged rollout costs +infinity; when both diverge the result is u_bar (the
/// solve then reports InitialRolloutDiverged). Throws std::invalid_argument when the policy's sizes
/// do not match the model or x0.
WarmStartControls warm_start_controls(const StepModel& model, const Cost& cost, const AffinePolicy& previous,
                                      const VectorCRef& x0);

}  // namespace gpilqg
