#pragma once
/// @file rollout.hpp
/// Simulating a step model forwards under a control sequence, with or without sampled noise.
///
/// With noise, each step draws xi ~ N(0, I_p) and xi_G ~ N(0, I_q) and applies the paper's
///   x' = phi(x, u) + F(x, u) xi sqrt(dt) + G(x, u) xi_G sqrt(dt).

#include <functional>
#include <random>
#include <string_view>

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

/// How a rollout ended. Every rollout in the project (open loop, policy, MPC, synthetic data) runs
/// through closed_loop_rollout and so through the same divergence test (check_divergence).
enum class RolloutStatus {
  Completed,           ///< every step was taken
  StateBoundExceeded,  ///< a state entry exceeded the bound (default kDivergedStateMagnitude): diverging
  NonFiniteState,      ///< a step produced NaN or inf (the model overflowed within one step)
  NonFiniteControl,    ///< the controller returned NaN or inf (e.g. huge gains on a large state)
};
std::string_view to_string(RolloutStatus status);

/// The bound on |x_i| beyond which a rollout counts as diverged: far above any physical state of the
/// systems here, and far enough below overflow that quadratic costs of the states stay finite
/// (1e12 squared is 1e24), so a diverging rollout is stopped before it poisons costs with inf or NaN.
inline constexpr double kDivergedStateMagnitude = 1e12;

/// The one divergence test: NonFiniteState when an entry of x is NaN or inf, StateBoundExceeded when
/// some |x_i| > max_magnitude, else Completed (meaning "fine").
RolloutStatus check_divergence(const VectorCRef& x, double max_magnitude = kDivergedStateMagnitude);

/// Rolls `model` out from x0 under the controls u (m x T). `rng` must be non-null unless
/// noise == None. Throws std::invalid_argument when sizes do not match the model. When the rollout
/// diverges (RolloutStatus) it stops with finite = false and the status says why: the states reached
/// so far are kept, the remaining state columns repeat the last state within the bound, the controls
/// after the stop are zero and a non-finite control is replaced by zero (so no NaN or inf is ever
/// returned), and `steps_completed` tells how far it went: x(:, 0..steps_completed) were reached under
/// u(:, 0..steps_completed-1).
struct RolloutResult {
  Trajectory trajectory;
  int steps_completed = 0;
  bool finite = true;  ///< status == Completed
  RolloutStatus status = RolloutStatus::Completed;
};

RolloutResult rollout(const StepModel& model, const VectorCRef& x0, const Matrix& u,
                      RolloutNoise noise = RolloutNoise::None, std::mt19937_64* rng = nullptr);

/// The control at step t from the state the controller observes, written into u (size m).
using Controller = std::function<void(int t, const VectorCRef& observed, VectorRef u)>;

/// The one closed-loop simulation loop of the project (open-loop rollouts, policy rollouts and MPC
/// all run through it): at each step the controller sees x_t plus N(0, diag(observation_std^2))
/// (no noise when empty), chooses u_t, and sample_step draws x_{t+1}. Divergence is handled as in
/// rollout(), with `max_state_magnitude` the bound of check_divergence. `rng` may be null only when
/// there is no noise of either kind. Throws std::invalid_argument for a non-finite x0 or a bound <= 0.
RolloutResult closed_loop_rollout(const StepModel& world, const VectorCRef& x0, int steps,
                                  const Controller& controller, RolloutNoise noise,
                                  const Vector& observation_std, std::mt19937_64* rng,
                                  double max_state_magnitude = kDivergedStateMagnitude);

/// One sampled step, the shared mechanism of every simulated rollout in the project:
///   x' = phi(x, u) [+ sqrt(dt) F(x, u) xi] [+ sqrt(dt) G(x, u) xi_G]
/// as `noise` selects (None: the mean step; rng may then be null). `scratch` holds the columns
/// between calls and `workspace` (model.make_workspace()) the model's scratch. Returns false when x' is
/// not finite (a diverging rollout).
bool sample_step(const StepModel& model, const VectorCRef& x, const VectorCRef& u, RolloutNoise noise,
                 DiffusionColumns& scratch, std::mt19937_64* rng, VectorRef x_next, StepWorkspace& workspace);

/// Adds N(0, diag(std^2)) to x (a measurement of the state); no-op when `std` is empty.
void add_observation_noise(const Vector& std, std::mt19937_64& rng, VectorRef x);

}  // namespace gpilqg
