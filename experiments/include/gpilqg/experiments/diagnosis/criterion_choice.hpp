#pragma once
/// @file criterion_choice.hpp
/// `--criterion auto`: the fit criterion (fit_criterion.hpp) and the simulation window chosen from
/// what the data are, by a fixed rule whose thresholds are dimensionless.
///
/// The rule, in order:
///
///  1. Simulation (output error) when the system is passive (no controls) or some state was estimated
///     from others (MeasurementSet::estimated_states, e.g. velocities `gpilqg data import`
///     differentiated from positions). A one-step fit regresses on the measured state: when the
///     velocities are filtered estimates, their errors are errors in the variables and bias the fit
///     (friction comes out too small), which the simulation from a measured start does not suffer
///     within a window. A free response carries its information in how it decays, which accumulates
///     over periods and is below the noise of one step for light damping.
///
///  2. Inverse-dynamics when the controls are generalised forces and the inverse-dynamics residual's
///     error per sample is at most a third of the one-step residual's (rho >= kInverseDynamicsRatio = 3),
///     else one-step.
///
///     Generalised forces: the model has a generalised-force map (generalised_forces.hpp), the
///     controls act only on the velocities of its coordinates, and b_v = W_v G with one gain matrix G
///     (k x m) at every measured state and control (G = W_v^-1 df_v/du, compared at up to 8 states
///     spread over the data and at a second control; relative tolerance 1e-4). So a motor with a gear
///     on a joint and the cart-pole's force qualify; a thrust turned by the attitude, a control that
///     drives a state of its own (an actuator's dynamics) or enters nonlinearly do not. Only then is
///     the residual r = W_v^-1 (qdd - f_v) the generalised force the model misses.
///
///     rho, per velocity state v of a force component (in acceleration units, so no scale cancels
///     wrongly), the smallest over them:
///
///       E_1^2  = 2 sigma_v^2 / dt^2         the one-step residual's noise: the difference of two
///                + mean_t |b_v(x_t) o sigma_u|^2   velocity samples of white noise sigma_v, over dt, and
///                                           the noise of the measured controls (sigma_u per control),
///                                           which both residuals carry alike. sigma_v and sigma_u are
///                                           medians of differences (robust_noise_std in the .cpp), so
///                                           the corners and steps held controls leave are not taken
///                                           for noise;
///       E_ID^2 = R_hat(w) + mean_t a_c,t^2  the acceleration estimate's error: its estimated mean
///                                           squared error (noise and bias, derivative_window.hpp, at
///                                           the window w the rule chooses) plus the error a control
///                                           that changes within the window causes,
///       a_c,t  = b_v(x_t) (K * u - u)_t,    K the smoothing the Savitzky-Golay derivative of window w
///                                           applies to the acceleration (its weights on the velocity
///                                           increments, centred, summing to 1).
///
///     A held command (zero-order hold) makes the acceleration jump at every change; the centred
///     estimate mixes both sides, and a_c measures exactly that. Controls sampled from a continuous
///     signal (measured joint torques) leave a_c of second order in the window. sigma_v and R_hat are
///     estimated from the velocity column itself, so rho depends on the noise, the sampling rate and
///     the motion only through the data: on the two-link arm at 1 kHz with smooth measured torques
///     rho = 13.6, and the actual ratio of the two residuals' errors under the true model is 13.6;
///     with the torques held for 20 ms rho = 0.90 (actual 0.72); the cart-pole test data (50 Hz, held
///     5 samples) give 0.18 (tests/experiments/criterion_choice_test.cpp).
///
///     Why 3: the pure noise ratio of the shortest window (w = 3) is sqrt(2) / (dt G(3)) = 2, so rho >= 3
///     needs a longer window, i.e. a signal smooth over several samples; and a factor 3 in error
///     (9 in variance) keeps the choice from flipping on the estimates of sigma_v and R_hat, which are
///     good to tens of percent. Below it one-step is kept: it needs no acceleration estimate and
///     integrates held controls exactly. The input delay of the model is not applied here: it shifts
///     the controls, not their smoothness.
///
///     Its instrumental-variable form (IDIM-IV, instrumental_variables.hpp) when least squares on the
///     force residual would be biased by the noise of the measured velocities by 1% or more
///     (lambda >= kInstrumentAttenuation): a friction linear in a velocity v, fitted by least squares
///     on the measured v + e, shrinks by the factor var(v) / (var(v) + sigma_v^2), so by
///
///       lambda = max over the velocity states of sigma_v^2 / var(v_measured)
///
///     to first order (sigma_v the robust noise level above, var over every sample). 1% is an accuracy
///     below which published friction values do not go; a smaller bias is left to least squares, which
///     needs no simulation of the model and has the smaller variance.
///
///  3. One-step otherwise.
///
/// The window W of the simulation criterion: two periods of the slowest motion of the velocity
/// states (motion_period.hpp), W = round(2 P / dt), clamped to [kMinWindow, cap]:
///  - two periods: a light damping's effect on the amplitude grows with the number of periods
///    simulated, and so does the phase error of a simulator whose frequency is off; over two periods
///    a frequency error of up to 1/8 drifts by less than a quarter period, short of the half period at
///    which the output error stops being a useful (convex) measure of the fit;
///  - at least kMinWindow = 5 samples: a shorter window is barely more than one step;
///  - cap: at most half the shortest episode (every episode holds two windows, so every episode
///    contributes more than one start); for a single record, cut into kHeldoutBlockCount blocks with a
///    gap of W samples at the held-out blocks (heldout_blocks.hpp), at most (L - 2) / 4 for blocks of
///    L samples, so a training block between two held-out blocks keeps at least two windows;
///  - a velocity state that never leaves its noise band does not count; one that moves but is slower
///    than every episode sets W to the cap.
///  When the cap is below 2 samples no window fits: one-step, with the reason saying so.
///
/// Velocity states: those of the model's generalised coordinates, else the states named `<q>_dot`
/// with `<q>` a state, else every state.

#include <limits>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/diagnosis/fit_criterion.hpp"

namespace gpilqg::diagnosis {

/// rho above which inverse-dynamics is chosen (file comment).
inline constexpr double kInverseDynamicsRatio = 3.0;
/// lambda at or above which inverse dynamics takes its instrumental-variable form (file comment).
inline constexpr double kInstrumentAttenuation = 0.01;
/// The shortest simulation window [samples].
inline constexpr int kMinWindow = 5;

/// What the rule measured, for the report.
struct CriterionFacts {
  double dt = 0.0;                            ///< the step of the first episode [s]
  bool passive = false;                       ///< no controls
  std::vector<std::string> estimated_states;  ///< MeasurementSet::estimated_states
  std::vector<std::string> velocity_states;   ///< the states the rule measured the motion in
  /// Why the controls are not generalised forces; empty when they are or when not asked (rule 1).
  std::string not_forces;
  bool forces_checked = false;                ///< rule 2 was reached
  double ratio = 0.0;                         ///< rho = min over velocity states of E_1 / E_ID (0: not measured)
  std::string ratio_state;                    ///< the velocity state of the minimum
  int acceleration_window = 0;                ///< its derivative window w [samples]
  double control_error = 0.0;                 ///< sqrt(mean a_c^2) / E_ID there: the held controls' share
  double slowest_period = 0.0;                ///< P of the slowest velocity state [s] (inf: slower than the episodes)
  std::string slowest_state;                  ///< that state
  int window_cap = 0;                         ///< the cap on W [samples]
  double attenuation = 0.0;                   ///< lambda = max sigma_v^2 / var(v) (rule 2, inverse dynamics)
  std::string attenuation_state;              ///< the velocity state of the maximum
};

struct CriterionChoice {
  FitCriterion criterion = FitCriterion::OneStep;
  int window = 1;      ///< W for the simulation criterion, else 1
  bool instruments = false;  ///< inverse dynamics in its instrumental-variable form (rule 2)
  std::string reason;  ///< one sentence for the report: the criterion and the facts that chose it
  CriterionFacts facts;
};

/// The criterion for fitting `model`'s effects to `data` (file comment). `data` must hold episodes of
/// at least 2 samples at one step (a set the readers accepted) of `model`'s system. Throws
/// std::invalid_argument for an empty set or a model whose states or controls differ in number from
/// the data's.
CriterionChoice choose_criterion(const MeasurementSet& data, const ModelSpec& model);

/// The cap on the simulation window for `data` (file comment): half the shortest episode, or for a
/// single episode of T samples (L - 2) / 4 with L = floor(T / kHeldoutBlockCount).
int simulation_window_cap(const MeasurementSet& data);

}  // namespace gpilqg::diagnosis
