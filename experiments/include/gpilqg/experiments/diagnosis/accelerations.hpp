#pragma once
/// @file accelerations.hpp
/// Zero-phase estimates of the accelerations qdd_t = d(qdot)/dt at every transition of a measurement
/// set, from the measured columns alone (no model): the input of the inverse-dynamics residual
/// (generalised_force_residual.hpp).
///
/// The rows of diagnosis Transitions are cut into segments of consecutive samples: a segment ends
/// where the episode changes or where a row's x_next is not the next row's x (a gap). A segment of
/// rows a .. b-1 holds the T = b - a + 1 samples x_a, ..., x_{b-1}, x_next_{b-1} of each column.
///
/// What is differentiated. Measured velocities once; but when every velocity was estimated from its
/// measured position (Transitions::position_of: an encoder drive or a robot logged as positions, whose
/// velocities `gpilqg data import` differentiated), the positions twice:
///
///   qdd_t = (1/dt) sum_{j=-h..h} c_j v_{t+j}       (derivative 1, of velocities), or
///   qdd_t = (1/dt^2) sum_{j=-h..h} c_j q_{t+j}     (derivative 2, of positions),
///
/// a Savitzky-Golay fit of degree p (2 unless the caller says otherwise) over w = 2h + 1 samples,
/// centred and therefore zero-phase (no lag) at every sample at least h from a segment's ends. The
/// positions carry the sensor's own noise, white (an encoder's count), with one filter whose weights
/// are known; an estimated velocity is already a filter's output, whose correlated noise the window
/// rule cannot see, and the chain of two filters (the import's and this one) would put on the
/// accelerations weights that parallel filtering (below) does not know. At the first and last h
/// samples the same fit over the first (last) w samples is evaluated off-centre: exact for
/// polynomials of degree <= p, with more noise (SavitzkyGolayDerivative::end_noise_gain).
///
/// One window for every column. derivative_window.hpp chooses a window per column from the data
/// (least estimated mean squared error, noise and bias both estimated from the column), pooled over all
/// segments, so it adapts to the sampling rate, the noise and the speed of the motion; every column is
/// then differentiated with the widest of these choices (never more than the shortest segment). One
/// filter for all columns is what parallel filtering needs (below): a control that drives several
/// coordinates, or a force that depends on the controls, is then filtered once, consistently with
/// every acceleration it enters. For the same reason positions are differentiated only when every
/// velocity was estimated from its position; with one velocity measured, all are differentiated once.
///
/// What the estimate is of: a weighted mean of the acceleration over the window, not the acceleration
/// at x_t. Writing each velocity sample as the first plus the increments before it,
///
///   qdd_t = (1/dt) sum_j c_j v_j = (1/dt) sum_s k_s (v_{s+1} - v_s),   k_s = sum_{j > s} c_j,
///
/// and an increment is dt times the mean acceleration over its step, which for a continuous signal is
/// (a_s + a_{s+1}) / 2 to second order and for a control held over the step (zero-order hold) is the
/// acceleration that control gives. So qdd_t = sum_r m_r a_r with the weights m of
/// acceleration_weights (summing to 1). From positions, by Taylor's formula with the integral
/// remainder about the window's first sample (the weights annihilate constants and lines),
///
///   qdd_t = (1/dt^2) sum_k c_k int_0^{k dt} (k dt - tau) a(tau) dtau = sum_r m_r a_r,
///   m_r = sum_k c_k beta_{k,r},
///
/// with, for an acceleration linear between samples (a continuous signal), beta_{k,0} = k/2 - 1/6,
/// beta_{k,r} = k - r for 0 < r < k, beta_{k,k} = 1/6 (k >= 1), and for one held over each step
/// beta_{k,r} = k - r - 1/2 for r < k; beta = 0 otherwise. Both are exact for accelerations of that
/// shape. A control that changes within the window makes a_r change with it, and the residual
/// Q_t - ID(x_t, qdd_t) would compare the force at t with the mean acceleration around t: an error as
/// large as the control's change over the window.
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

/// The one derivative filter of an acceleration estimate (file comment).
struct AccelerationFilter {
  int window = 0;      ///< w, odd: the fits span w samples; 0 for no filter (the accelerations as they are)
  int order = 2;       ///< p, the degree of the fits
  int derivative = 1;  ///< 1: of the velocities; 2: of the positions
};

/// The columns an acceleration estimate differentiates (file comment): the measured positions of
/// `velocity_states` (derivative 2) when `position_of` (Transitions::position_of) names one for every
/// one of them, else the velocity states themselves (derivative 1).
struct DifferentiatedColumns {
  std::vector<int> states;  ///< one per velocity state, in its order
  int derivative = 1;
};
DifferentiatedColumns differentiated_columns(const std::vector<int>& position_of, const std::vector<int>& velocity_states);

struct AccelerationEstimate {
  Matrix qdd;                            ///< N x c: d(x_j)/dt at x_t of every row t, column k for velocity_states[k]
  std::vector<int> velocity_states;      ///< the velocity states x_j, in the caller's order
  std::vector<int> differentiated_states;  ///< the columns differentiated for them: themselves or their positions
  std::vector<DerivativeWindow> windows;  ///< the window rule's choice for each of them
  int window = 0;                        ///< the one window every column was differentiated with (the widest)
  int order = 2;                         ///< the degree of the fits
  int derivative = 1;                    ///< 1: velocities differentiated; 2: positions, twice
  AccelerationFilter filter() const { return {window, order, derivative}; }
};

/// How a control acts over the step between two samples.
enum class ControlHold {
  Continuous,  ///< a continuous signal sampled (measured torques): the step's mean is (u_s + u_{s+1}) / 2
  ZeroOrder,   ///< held from one sample to the next (a command): the step's value is u_s
};

/// m_0 .. m_{w-1}: the weights the derivative of `filter` evaluated at `position` (0 .. w-1) of its
/// window puts on the accelerations at the window's samples (file comment), summing to 1. Of
/// velocities (derivative 1), continuous: m_r = (k_{r-1} + k_r) / 2 with k_{-1} = k_{w-1} = 0;
/// zero-order hold: m_r = k_r, m_{w-1} = 0. Of positions (derivative 2): m_r = sum_k c_k beta_{k,r}.
Vector acceleration_weights(const SavitzkyGolayDerivative& filter, int position, ControlHold hold);

/// The controls `u` (N x m, one row per row of `data`, e.g. applied_controls) seen through the
/// acceleration estimate's filter `filter` (window > 0; file comment: parallel filtering):
/// at every row the weights of acceleration_weights at the row's place in its window, over the controls
/// of the window's rows; the window's last sample at a segment's end (x_next of its last row) takes
/// that row's control. Throws std::invalid_argument when `u` does not have one row per transition or a
/// segment is shorter than the window.
Matrix filtered_controls(const Transitions& data, const Matrix& u, const AccelerationFilter& filter,
                         ControlHold hold = ControlHold::Continuous);

/// The same for any signal sampled at the rows of `data` (`y`, N x c: controls, or the model's forces
/// at the measured states), at the rows `rows` only (rows.size() x c, in their order). Throws
/// std::invalid_argument as filtered_controls does, and for a row outside the data.
Matrix filtered_at(const Transitions& data, const Matrix& y, const std::vector<int>& rows,
                   const AccelerationFilter& filter, ControlHold hold = ControlHold::Continuous);

/// Rows at which a coordinate stands still (N x c, column k for velocity_states[k]): every velocity
/// sample that the acceleration filter `filter` reads at the row (its window, off-centre at a segment's
/// ends) lies within
///
///   |v| <= kStandstillSpeed rms(v),
///
/// rms(v) the column's rms about 0 over every sample: at rest, or creeping at a hundredth of the speeds
/// it moves at, for the whole window. A dry friction there is static: it holds the coordinate with
/// whatever force the others leave, anywhere within its breakaway force, and a creeping contact's force
/// turns with velocities far below what an estimate from counts or a filter resolves; no model of
/// sliding friction predicts either (a carriage at rest between two moves, held against a constant
/// force and the loop's small error). Robot and drive identification leave such samples out of the
/// inverse-dynamics fit. A coordinate passing through 0 at a reversal is not at rest: its velocity
/// leaves the band within the window. A velocity whose noise exceeds the band at rest (measured with
/// noise above a hundredth of its rms) is never taken to rest: its rows stay, as they would without
/// this test; the band is not widened to the noise, which would take a slow but real motion for rest.
Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> standstill_rows(const Transitions& data,
                                                                   const std::vector<int>& velocity_states,
                                                                   const AccelerationFilter& filter);

/// The band of standstill_rows: a hundredth of the coordinate's rms speed, two decades below the
/// speeds it moves at (the lower end of the Coulomb friction's smoothing grid, velocity_scales.hpp, is
/// a fifth of that).
inline constexpr double kStandstillSpeed = 0.01;

/// The accelerations of every row of `data` for the velocity states `velocity_states` (file comment:
/// from them, or from their measured positions, differentiated_columns), sampled at `dt`, with fits of
/// degree `order`. Throws std::invalid_argument for a column outside the
/// state, dt not finite and positive, rows whose times t are not dt apart within a segment (naming the
/// episode and both steps), or a segment with fewer samples than shortest_differentiable_segment(order)
/// (naming its episode, its rows and its length): never a NaN.
AccelerationEstimate estimate_accelerations(const Transitions& data, const std::vector<int>& velocity_states, double dt,
                                            int order = 2);

}  // namespace gpilqg::diagnosis
