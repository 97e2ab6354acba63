#pragma once
/// @file policy_rollout.hpp
/// A policy file run on a simulated world, logged as a robot would log it (`gpilqg rollout`), so that
/// the loop of plan, run, log, plan again can be tried without hardware. The log holds what the
/// controller saw (the measured states) and the controls it applied, in the data format of
/// docs/formats.md.

#include <cstdint>
#include <vector>

#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/step_model.hpp"
#include "gpilqg/experiments/policy_file.hpp"

namespace gpilqg {

/// What to roll out: a policy file's law on a world, for a number of episodes.
struct PolicyRolloutRequest {
  const PolicyFile* policy = nullptr;  ///< its law (AffinePolicy::control), limits, dt and round
  const StepModel* world = nullptr;    ///< steps of the policy's dt; samples its process noise at every step
  SystemSignature system;              ///< the log's system
  Vector x0;                           ///< the initial state of every episode
  int episodes = 1;
  Vector exploration_std;              ///< Gaussian noise added to every control (empty: none), then clamped
  Vector observation_std;              ///< noise on every measured state (empty: none)
  /// When set, the task cost of each finite episode's true trajectory (true states, applied controls).
  const Cost* task_cost = nullptr;
  /// Episode r draws from data_rollout_rng(seed, 0, "gp_ilqg", policy round, r) (run_setup.hpp): the
  /// stream of data rollout r after the plan of that round in `gpilqg run`.
  std::uint64_t seed = 1;
};

/// What the episodes gave.
struct PolicyRolloutResult {
  /// The episodes with at least one step, episode id r for episode r: one row per step up to the last
  /// finite state; the last row repeats the last control (no transition starts there).
  MeasurementSet log;
  std::vector<double> costs;  ///< the finite task costs of the finite episodes, in episode order
  int diverged = 0;           ///< episodes whose world diverged (kept up to their last finite state)
  int dropped = 0;            ///< episodes that diverged at their first step (left out of the log)
  int overflowed = 0;         ///< finite episodes whose task cost is not a finite number
};

/// Rolls the policy out on the world request.episodes times (task_actions.hpp's roll_out: the
/// controller sees the measured state, exploration is added to its control and the sum clamped to
/// the policy's limits). Throws std::invalid_argument when the policy or the world is missing or x0
/// is not a state of the policy.
PolicyRolloutResult roll_out_policy(const PolicyRolloutRequest& request);

}  // namespace gpilqg
