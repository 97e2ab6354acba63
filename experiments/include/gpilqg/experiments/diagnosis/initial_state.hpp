#pragma once
/// @file initial_state.hpp
/// The simulation criterion with each window's initial state estimated (to first order) instead of
/// taken as measured: the error that a better start would remove is not counted.
///
/// Under the simulation criterion (simulation_error.hpp) window w starts from the measured state
/// x_{s0}, which carries the measurement noise. Its error grows along the simulation, by the
/// sensitivity S_r = d x_hat_{r+1} / d x_{s0} (n x n) of row r of the window, and on a lightly damped
/// or chaotic system it can be as large as the effect sought: the fit then trades a physical
/// parameter against the noise of the starts. Output-error identification estimates the start with
/// the parameters (MATLAB `pem`/`oe` with `InitialCondition` 'estimate'). Here the start is eliminated
/// in closed form, to first order around the measured state:
///
///   e_w(theta) ~ e_w(theta; x_{s0}) - S_w d,   min_d |e_w - S_w d|^2  =>  e~_w = (I - P_w) e_w,
///
/// with e_w the weighted errors of the window's rows stacked (sqrt(w_i) e_{r,i}), S_w their weighted
/// sensitivities stacked the same way and P_w the orthogonal projector onto the columns of S_w. The
/// sensitivities are those of the given model (the base model of the diagnosis) at the measured
/// starts, by central differences, computed once: this is the variable-projection elimination of n
/// nuisance parameters per window with the Jacobian of the nuisance frozen (Kaufman's simplification
/// of Golub-Pereyra), exact for a change of start that the model's linearisation describes, which a
/// start error at the noise level is. The criterion is then the simulation error of the best start
/// near the measured one: the part of an effect's signature that a different start could mimic does
/// not count for it, the part that accumulates along the window (a decay, a drift) does.
///
/// Each window removes n of its W n weighted errors; a window whose sensitivity could not be computed
/// (a perturbed simulation diverged, or not finite) keeps its errors as they are.

#include <vector>

#include "gpilqg/core/types.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg::diagnosis {

/// The weighted sensitivities of every row's simulated prediction to its window's initial state.
struct InitialStateSensitivity {
  int window = 0;                 ///< W, the rows of a window (simulation_error.hpp)
  std::vector<int> window_of_row; ///< N entries: the index of the row's window, windows numbered in row order
  /// (N n) x n: row r n + i is sqrt(w_i) d x_hat_{r+1,i} / d x_{s0} of row r's window; a window whose
  /// sensitivity is unusable is zero.
  Matrix weighted;
};

/// The sensitivities of `model` driven by `u` over the windows of `window` rows of `data` (the windows
/// of simulated_predictions over all rows), weighted by sqrt(weights). Central differences with the
/// step 1e-6 (1 + rms of state j) in start component j.
InitialStateSensitivity initial_state_sensitivity(const StepModel& model, const Transitions& data, const Matrix& u,
                                                  int window, const Vector& weights);

/// Removes from `weighted` (the weighted errors of `rows` stacked row by row, index k n + i) the
/// part a change of each window's start explains: e~_w = (I - P_w) e_w over the rows of window w
/// present in `rows` (consecutive rows of one window form its block).
void remove_start_error(const InitialStateSensitivity& sensitivity, const std::vector<int>& rows, Vector& weighted);

/// The same on errors in the data's units: `errors` (rows.size() x n) weighted by sqrt(weights), the
/// start error removed, weighted back.
Matrix without_start_error(const InitialStateSensitivity& sensitivity, const std::vector<int>& rows, const Matrix& errors,
                           const Vector& weights);

}  // namespace gpilqg::diagnosis
