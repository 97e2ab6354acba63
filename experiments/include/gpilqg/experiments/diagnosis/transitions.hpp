#pragma once
/// @file transitions.hpp
/// The one-step transitions of a measurement set, split into training and held-out episodes, and the
/// predictions of a model on them: one-step x'_hat = phi(x_t, u_t) and k-step open-loop predictions over
/// windows restarted from measured states.
///
/// Held-out data are whole episodes, never single samples: consecutive samples of one episode are
/// strongly correlated, so a sample split would leak the held-out data into the fit. A file of a single
/// episode is cut into blocks first (heldout_blocks.hpp), and the blocks are the episodes here.

#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg::diagnosis {

/// Every pair (x_t, u_t) -> x_{t+1} of consecutive rows, over all episodes, in file order.
struct Transitions {
  Matrix x;                   ///< N x n, measured state at t
  Matrix u;                   ///< N x m, control applied from t
  Matrix x_next;              ///< N x n, measured state at t + dt
  Vector t;                   ///< N, time of x
  std::vector<int> episode;   ///< N, index of the episode in MeasurementSet::episodes
  std::vector<bool> heldout;  ///< N, true for rows of held-out episodes
  /// n or empty (every state measured): for a velocity `<q>_dot` estimated from its measured position
  /// `<q>` (MeasurementSet::estimated_states, e.g. by `gpilqg data import`), the column of `<q>`; -1
  /// for every other state (estimated_velocity_positions).
  std::vector<int> position_of;
  int size() const { return static_cast<int>(x.rows()); }
  /// Indices of the training rows (heldout == false) or of the held-out rows.
  std::vector<int> rows(bool heldout_rows) const;
};

/// The held-out episodes (indices into MeasurementSet::episodes): every episode whose position i
/// satisfies (i + 1) * fraction crossing an integer, i.e. round(E * fraction) episodes spread evenly
/// over the file, at least one and at least one left for training (heldout_indices, heldout_blocks.hpp).
/// Throws std::invalid_argument when the set has fewer than 2 episodes or fraction is outside (0, 1).
std::vector<int> heldout_episodes(const MeasurementSet& set, double fraction);

/// The state `<q>` whose velocity the state `<q>_dot` at `velocity` is by its name, -1 when there is none.
int position_by_name(const SystemSignature& system, int velocity);

/// Transitions::position_of for `set`: per state, the column of the measured position `<q>` of a
/// velocity `<q>_dot` in set.estimated_states whose `<q>` is not, else -1; empty when every state was
/// measured.
std::vector<int> estimated_velocity_positions(const MeasurementSet& set);

/// The transitions of `set`, with held-out rows marked and the states' provenance (position_of). Throws std::invalid_argument when an episode's
/// dt differs from `dt` by more than 1e-6 relative (naming the episode and both values).
Transitions make_transitions(const MeasurementSet& set, const std::vector<int>& heldout, double dt);

/// Throws std::invalid_argument when a state or control of `set` exceeds |value| <= kDivergedStateMagnitude
/// (1e12, control/rollout.hpp), naming the episode, the time and the column: a measurement beyond the
/// bound at which every prediction counts as diverged is not a measurement of a physical system, and
/// the squares of its differences overflow (1e308 - (-1e308) is inf).
void check_measurement_range(const MeasurementSet& set);

/// Whether a predicted state diverged: not finite or beyond kDivergedStateMagnitude (rollout.hpp's
/// check_divergence, the one test shared with every rollout).
bool prediction_diverged(const VectorCRef& x);

/// The inputs a system with an input delay of `delay` control periods applies at every row (N x m):
/// delay_controls (input_delay.hpp) within each episode; data.u for 0.
Matrix applied_controls(const Transitions& data, double delay);

/// One-step predictions phi(x_t, u_t) (N x n), u_t the applied input (applied_controls with
/// `input_delay`). A prediction that diverged (prediction_diverged) is replaced by x_t and counted in
/// `diverged` when not null, so no NaN, inf or overflowing value leaves this function.
Matrix one_step_predictions(const StepModel& model, const Transitions& data, int* diverged = nullptr,
                            double input_delay = 0.0);

/// k-step open-loop predictions: for every episode and every start s = 0, stride, 2 stride, ... with
/// s + k < T, roll the model k steps from the measured x_s with the measured controls (delayed by
/// `input_delay` control periods, input_delay.hpp) and compare with the measured x_{s+k}.
struct KStepPredictions {
  int k = 1;
  Matrix measured;             ///< W x n, x_{s+k}
  Matrix predicted;            ///< W x n
  std::vector<int> episode;    ///< W
  std::vector<int> start;      ///< W, s
  int diverged = 0;            ///< windows whose prediction diverged (prediction_diverged; left out of the W rows)
};
KStepPredictions k_step_predictions(const StepModel& model, const MeasurementSet& set,
                                    const std::vector<int>& episodes, int k, int stride, double input_delay = 0.0);

}  // namespace gpilqg::diagnosis
