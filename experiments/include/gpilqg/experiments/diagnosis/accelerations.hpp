#pragma once
/// @file accelerations.hpp
/// Zero-phase estimates of the accelerations qdd_t = d(qdot)/dt at every transition of a measurement
/// set, from the measured velocity columns alone (no model): the input of the inverse-dynamics
/// residual (generalised_force_residual.hpp).
///
/// The rows of diagnosis Transitions are cut into segments of consecutive samples: a segment ends
/// where the episode changes or where a row's x_next is not the next row's x (a gap). A segment of
/// rows a .. b-1 holds the T = b - a + 1 velocity samples x_a, ..., x_{b-1}, x_next_{b-1} of each
/// column. Each velocity column v is differentiated with a Savitzky-Golay fit of degree p (2 unless
/// the caller says otherwise):
///
///   qdd_t = (1/dt) sum_{j=-h..h} c_j v_{t+j}    (window w = 2h + 1, c antisymmetric),
///
/// centred and therefore zero-phase (no lag) at every sample at least h from a segment's ends, exact
/// for every velocity that is a polynomial of degree <= p in time. At the first and last h samples the
/// same fit over the first (last) w samples is evaluated off-centre: still exact for such polynomials,
/// with more noise (SavitzkyGolayDerivative::end_noise_gain). The window is chosen per column from the
/// data by derivative_window.hpp (least estimated mean squared error, noise and bias both estimated
/// from the column), pooled over all segments, so it adapts to the sampling rate, the noise and the
/// speed of the motion; it never exceeds the shortest segment.
///
/// What the estimate is of: the derivative of the velocity signal around t, which is the acceleration
/// at x_t when the motion is smooth over the window. A control held constant between samples (zero
/// order hold) makes the true acceleration jump at every change of the control; the centred estimate
/// there mixes both sides, so rows within h samples of large control steps carry that error. Controls
/// sampled from a continuous signal (measured joint torques) do not.

#include <vector>

#include "gpilqg/experiments/diagnosis/derivative_window.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

/// Consecutive rows [first, end) of Transitions that form one uniformly sampled record.
struct RowSegment {
  int first = 0;
  int end = 0;
  int episode = 0;  ///< Transitions::episode of its rows
  int samples() const { return end - first + 1; }  ///< the states x_first .. x_{end-1} and x_next_{end-1}
};

/// The segments of `data` (file comment): maximal runs of rows of one episode with x_next of each row
/// equal to x of the next.
std::vector<RowSegment> row_segments(const Transitions& data);

struct AccelerationEstimate {
  Matrix qdd;                            ///< N x c: d(x_j)/dt at x_t of every row t, column k for velocity_states[k]
  std::vector<int> velocity_states;      ///< the state columns x_j differentiated, in the caller's order
  std::vector<DerivativeWindow> windows;  ///< the window rule's choice for each of them
};

/// The accelerations of every row of `data` from the state columns `velocity_states` (file comment),
/// sampled at `dt`, with fits of degree `order`. Throws std::invalid_argument for a column outside the
/// state, dt not finite and positive, rows whose times t are not dt apart within a segment (naming the
/// episode and both steps), or a segment with fewer samples than shortest_differentiable_segment(order)
/// (naming its episode, its rows and its length): never a NaN.
AccelerationEstimate estimate_accelerations(const Transitions& data, const std::vector<int>& velocity_states, double dt,
                                            int order = 2);

}  // namespace gpilqg::diagnosis
