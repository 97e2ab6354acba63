#pragma once
/// @file resampling.hpp
/// Irregularly timed samples onto a fixed step (docs/data-import.md): split a record at its gaps,
/// lay a uniform grid over each piece, interpolate states linearly and hold controls.
///
/// Samples y_i at strictly increasing times t_0 < t_1 < ... are mapped onto the grid
/// tau_k = t_0 + k dt, k = 0 .. K-1, with K - 1 = floor((t_last - t_0) / dt + 1e-9) (the grid never
/// runs past the last sample, so nothing is extrapolated):
/// - linear:  y(tau) = y_i + (tau - t_i) (y_{i+1} - y_i) / (t_{i+1} - t_i) for t_i <= tau <= t_{i+1},
///   exact for signals linear in time;
/// - zero-order hold: y(tau) = y_i with i the last sample at or before tau, i.e. the control in
///   force at tau (a control logged at t_i is applied from t_i until the next sample);
/// - step average: y_k = (1 / dt) * integral over [tau_k, tau_k + dt) of the held signal, the constant
///   input with the same impulse over the step. It equals the hold when every switch is on the grid,
///   and differs from it only in steps where a logged (jittered) switch falls inside the step.

#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// A run of consecutive samples [begin, end) (indices into the time vector).
struct SampleRange {
  long begin = 0;
  long end = 0;
  long size() const { return end - begin; }
};

/// Splits samples at every step t_{i+1} - t_i > max_gap, so each range has no gap longer than
/// max_gap. `t` must be strictly increasing (std::invalid_argument otherwise); an empty `t` gives no
/// range.
std::vector<SampleRange> split_at_gaps(const VectorCRef& t, double max_gap);

/// The number of points of uniform_grid(t, dt), as a double so that a tiny dt over a long span
/// cannot overflow: callers check it against a limit before the grid is allocated.
double uniform_grid_size(const VectorCRef& t, double dt);

/// The grid tau_k = t(0) + k dt over [t(0), t(last)] as described above; t non-empty, dt > 0.
Vector uniform_grid(const VectorCRef& t, double dt);

/// Each column of `y` (rows = samples at times `t`) linearly interpolated at `tau` (within [t_0, t_last]).
Matrix interpolate_linear(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau);

/// Each column of `y` held from its sample time to the next (zero-order hold), read at `tau` (>= t_0).
Matrix hold_zero_order(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau);

/// The step average of each column of `y` held from its sample times, over [tau_k, tau_k + dt);
/// past the last sample the last value is held.
Matrix average_held(const VectorCRef& t, const MatrixCRef& y, const VectorCRef& tau, double dt);

/// The median of the steps t_{i+1} - t_i over the given ranges (0 when no range has two samples).
double median_step(const VectorCRef& t, const std::vector<SampleRange>& ranges);

}  // namespace gpilqg
