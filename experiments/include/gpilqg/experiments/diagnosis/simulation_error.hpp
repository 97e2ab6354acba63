#pragma once
/// @file simulation_error.hpp
/// The criterion that fits and scores effects (effect_fit.hpp): the one-step error, or the simulation
/// (output) error over windows of W samples, by multiple shooting from measured states.
///
/// One-step (W = 1). Row r's prediction is one step of the model from the measured state:
///
///   x_hat_{r+1} = phi(x_r, u_r; theta),   e_r = x_{r+1} - x_hat_{r+1}.
///
/// Simulation over windows of W samples. Each episode is cut into windows of W consecutive rows,
/// starting at its first row (rows s = 0, W, 2W, ... of the episode; the last window may be shorter).
/// Within a window the model runs open loop from the measured state at the window's first row s0,
/// driven by the measured inputs (delayed as the model applies them):
///
///   x_hat_{s0} = x_{s0},   x_hat_{r+1} = phi(x_hat_r, u_r; theta)   for r = s0, ..., s0 + W - 1,
///   e_r = x_{r+1} - x_hat_{r+1},
///
/// so e_r is the error of an (r - s0 + 1)-step simulation. This is multiple shooting with the shooting
/// nodes fixed at the measurements (the simulation fit of MATLAB's `compare` over horizons of W
/// samples, and the output-error criterion of `pem` for W = the episode length). Windows restart at
/// every episode start and wherever a row set skips rows, so a window never crosses a gap; since the
/// windows are fixed by the position in the episode, the prediction of a row is the same whether it
/// is computed over all rows or over the training or held-out rows alone.
///
/// The start. The measured x_{s0} carries the sensor's noise, and its error grows along the window
/// (on a chaotic system, exponentially). criterion_context therefore estimates each window's start to
/// first order about the measured one (initial_state.hpp): every simulation error of the fit, the
/// ranking and the verdict is the error from the best start near x_{s0}, as `pem` estimates the initial
/// state. simulated_predictions itself starts from the measurement.
///
/// Everything else of the fit is unchanged, with e_r in place of the one-step residual: the weighted
/// objective S(theta) = sum_r sum_i w_i e_{r,i}^2, its least-squares regressor J = d x_hat / d theta
/// (now the sensitivity of the simulation, accumulated through the window), the BOBYQA refit, the
/// intervals (Gauss-Newton, widened to the delete-one-episode jackknife, which is what keeps them
/// honest: the errors within a window are strongly correlated) and the held-out explained share with
/// its batch-means z score, whose batches are whole windows (the batch length is rounded up to a
/// multiple of W).
///
/// Why. An effect that changes one step by much less than the noise (light damping: a relative energy
/// loss of 4 pi zeta per period) is invisible in the one-step error, but its effect on the state
/// accumulates over a window, roughly W times larger after W steps, while the error of the start (the
/// measurement noise of x_{s0}) does not grow for a lightly damped system. The longer the window the
/// more the effect shows, and the more a wrong start or a chaotic system spoils it: pick W of the
/// order of a few periods of the slowest motion, shorter than the time over which the model
/// diverges from the data.
///
/// Weights. w_i = 1 / sigma_i^2 with sigma_i the one-step noise floor in either criterion: they set
/// the units in which the errors of the states are added up. The simulation errors are larger than
/// sigma_i, so under the simulation criterion the weighted objective is no chi-square; the explained
/// share and its z score do not depend on the overall scale of the weights.
///
/// Divergence. A simulated state that diverges (prediction_diverged) is replaced by the measured
/// x_r, as a one-step prediction that diverges is, and the simulation restarts from the measurement
/// x_{r+1} at the next row; such restarts are counted.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/fit_criterion.hpp"

namespace gpilqg::diagnosis {

/// Predictions of `rows` of `data` (rows.size() x n), windows of `window` rows (see the file comment;
/// window = 1 gives one_step_predictions), the model driven by `u` (N x m, applied_controls). A
/// diverged simulated state is replaced by the measured x_r and the next row restarts from the
/// measurement; `restarts` (when not null) receives their number. Throws std::invalid_argument for
/// window < 1.
Matrix simulated_predictions(const StepModel& model, const Transitions& data, const Matrix& u,
                             const std::vector<int>& rows, int window, int* restarts = nullptr);

/// All rows of `data` (0, ..., N - 1).
std::vector<int> all_rows(const Transitions& data);

/// The rows `rows` of `y` in their order (rows.size() x y.cols()).
Matrix rows_of(const Matrix& y, const std::vector<int>& rows);

}  // namespace gpilqg::diagnosis
