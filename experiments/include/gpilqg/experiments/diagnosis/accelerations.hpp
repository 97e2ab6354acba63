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
/// with more noise (SavitzkyGolayDerivative::end_noise_gain).
///
/// One window for every column. derivative_window.hpp chooses a window per column from the data
/// (least estimated mean squared error, noise and bias both estimated from the column), pooled over all
/// segments, so it adapts to the sampling rate, the noise and the speed of the motion; every column is
/// then differentiated with the widest of these choices (never more than the shortest segment). One
/// filter for all columns is what parallel filtering needs (below): a control that drives several
/// coordinates, or a force that depends on the controls, is then filtered once, consistently with
/// every acceleration it enters.
///
/// What the estimate is of: a weighted mean of the acceleration over the window, not the acceleration
/// at x_t. Writing each velocity sample as the first plus the increments before it,
///
///   qdd_t = (1/dt) sum_j c_j v_j = (1/dt) sum_s k_s (v_{s+1} - v_s),   k_s = sum_{j > s} c_j,
///
/// and an increment is dt times the mean acceleration over its step, which for a continuous signal is
/// (a_s + a_{s+1}) / 2 to second order and for a control held over the step (zero-order hold) is the
/// acceleration that control gives. So qdd_t = sum_r m_r a_r with the weights m of
/// acceleration_weights (summing to 1). A control that changes within the window makes a_r change
/// with it, and the residual Q_t - ID(x_t, qdd_t) would compare the force at t with the mean
/// acceleration around t: an error as large as the control's change over the window.
///
/// Parallel filtering (Gautier 1997; IDIM practice filters the torques and every column of the
/// observation matrix with one low-pass filter): the model's generalised force at every sample of the
/// window, controls included, is seen through the same weights, g~_t = sum_r m_r g_r (filtered_at;
/// filtered_controls for the controls alone), so that force and acceleration are both the window's
/// mean (criteria/inverse_dynamics.hpp). Exact when the inertia changes little over the window; the
/// weights assume a continuous signal (measured torques); for held controls they differ by half a
/// sample, which criterion_choice.hpp charges to the criterion when it chooses.

#include <vector>

#include "gpilqg/core/savitzky_golay.hpp"
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
  int window = 0;                        ///< the one window every column was differentiated with (the widest)
  int order = 2;                         ///< the degree of the fits
};

/// How a control acts over the step between two samples.
enum class ControlHold {
  Continuous,  ///< a continuous signal sampled (measured torques): the step's mean is (u_s + u_{s+1}) / 2
  ZeroOrder,   ///< held from one sample to the next (a command): the step's value is u_s
};

/// m_0 .. m_{w-1}: the weights the derivative of `filter` evaluated at `position` (0 .. w-1) of its
/// window puts on the accelerations at the window's samples (file comment), summing to 1. Continuous:
/// m_r = (k_{r-1} + k_r) / 2 with k_{-1} = k_{w-1} = 0; zero-order hold: m_r = k_r, m_{w-1} = 0.
Vector acceleration_weights(const SavitzkyGolayDerivative& filter, int position, ControlHold hold);

/// The controls `u` (N x m, one row per row of `data`, e.g. applied_controls) seen through the
/// acceleration estimate of window `window` and degree `order` (file comment: parallel filtering):
/// at every row the weights of acceleration_weights at the row's place in its window, over the controls
/// of the window's rows; the window's last sample at a segment's end (x_next of its last row) takes
/// that row's control. Throws std::invalid_argument when `u` does not have one row per transition or a
/// segment is shorter than the window.
Matrix filtered_controls(const Transitions& data, const Matrix& u, int window, int order = 2,
                         ControlHold hold = ControlHold::Continuous);

/// The same for any signal sampled at the rows of `data` (`y`, N x c: controls, or the model's forces
/// at the measured states), at the rows `rows` only (rows.size() x c, in their order). Throws
/// std::invalid_argument as filtered_controls does, and for a row outside the data.
Matrix filtered_at(const Transitions& data, const Matrix& y, const std::vector<int>& rows, int window, int order = 2,
                   ControlHold hold = ControlHold::Continuous);

/// The accelerations of every row of `data` from the state columns `velocity_states` (file comment),
/// sampled at `dt`, with fits of degree `order`. Throws std::invalid_argument for a column outside the
/// state, dt not finite and positive, rows whose times t are not dt apart within a segment (naming the
/// episode and both steps), or a segment with fewer samples than shortest_differentiable_segment(order)
/// (naming its episode, its rows and its length): never a NaN.
AccelerationEstimate estimate_accelerations(const Transitions& data, const std::vector<int>& velocity_states, double dt,
                                            int order = 2);

}  // namespace gpilqg::diagnosis
