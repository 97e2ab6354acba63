#pragma once
/// @file policy.hpp
/// The time-varying affine feedback policy DDP returns, and its closed-loop rollout on a possibly
/// different ("real") system:
///
///   u_t(x) = clamp( u_bar_t + k_t + K_t (x - x_bar_t),  u_min, u_max ).
///
/// After a converged solve k = 0 and (x_bar, u_bar) is the optimised nominal trajectory; inside the
/// line search the engine uses the same type with alpha k.

#include <random>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/control/trajectory.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

struct AffinePolicy {
  Matrix x_bar;              ///< n x (T+1) nominal states
  Matrix u_bar;              ///< m x T nominal controls
  Matrix k;                  ///< m x T feed-forward corrections
  std::vector<Matrix> K;     ///< T gains, each m x n
  Vector u_min, u_max;       ///< limits (empty: none)

  int horizon() const { return static_cast<int>(u_bar.cols()); }
  /// u_t(x) written into u (size m), with the feed-forward scaled by `alpha`.
  void control(int t, const VectorCRef& x, VectorRef u, double alpha = 1.0) const;
  /// Largest change between two policies: max over t of |u_bar + k| differences and of |K| entries,
  /// the "policy change" Delta pi of the paper's Algorithm 1.
  double distance(const AffinePolicy& other) const;
};

struct PolicyRolloutSettings {
  bool process_noise = true;      ///< sample the model's noise columns F
  bool uncertainty = false;       ///< also sample its uncertainty columns G
  Vector observation_std;         ///< the policy sees x + N(0, diag(std^2)) (empty: exact state)
  /// What sample_step draws, from the two flags above.
  RolloutNoise noise() const;
};

/// Runs the policy in closed loop on `world` from x0 (the world may differ from the model the policy
/// was computed on, e.g. the real-world preset, and may be integrated with sub-steps). The trajectory
/// holds the true states and the applied controls. A diverging rollout stops and says so.
using PolicyRollout = RolloutResult;
PolicyRollout rollout_policy(const StepModel& world, const AffinePolicy& policy, const VectorCRef& x0,
                             const PolicyRolloutSettings& settings, std::mt19937_64& rng);

/// The controls `policy` applies in closed loop on `model`'s mean step from x0 (m x T, within the
/// policy's limits): replayed open loop on the same model they give the same trajectory, so they are
/// how a policy made on one model becomes a start of a solve on another (a plan's feedback keeps it
/// near its nominal path where its open-loop controls would not). After a divergence the controls are
/// zero (rollout()).
Matrix closed_loop_controls(const StepModel& model, const AffinePolicy& policy, const VectorCRef& x0);

}  // namespace gpilqg
