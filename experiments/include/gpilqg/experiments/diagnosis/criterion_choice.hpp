#pragma once
/// @file criterion_choice.hpp
/// `--criterion auto`: the fit criterion (fit_criterion.hpp) and the simulation window chosen from
/// what the data are, by a fixed rule whose thresholds are dimensionless.
///
/// The rule, in order:
///
///  1. Simulation (output error) when the system is passive (no controls): a free response carries its
///     information in how it decays, which accumulates over periods and is below the noise of one step
///     for light damping.
///
///  2. Inverse-dynamics when the controls are generalised forces and the accelerations can be estimated
///     well enough. Always: the filter follows the model, i.e. its window keeps the motion (kappa >=
///     kMotionKept = 0.9, below) and its misfit on the model is small against the force the controls
///     apply (eps <= kFilterMisfit = 0.03, below), a residual the criterion leaves on a true model and
///     that therefore biases the fit; and, depending on whether the velocities were measured:
///      - measured velocities: the inverse-dynamics residual's error per sample is at most a third of
///        the one-step residual's (rho >= kInverseDynamicsRatio = 3), else one-step (rule 4);
///      - velocities estimated from positions (MeasurementSet::estimated_states, e.g. differentiated
///        by `gpilqg data import`: an encoder drive or a robot logged as positions and motor
///        commands, which robot and drive identification fits by IDIM): kappa and eps alone, always in the
///        instrumental-variable form; else simulation (rule 3). The per-sample noise of rho
///        means nothing here: an estimated velocity is already filtered, so its differences (E_1) are
///        far smoother than its errors, and one-step is no alternative anyway (rule 3).
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
///                                           the noise of the measured controls (sigma_u per control).
///                                           sigma_v and sigma_u are medians of differences
///                                           (robust_noise_std in the .cpp), so the corners and steps
///                                           held controls leave are not taken for noise;
///       E_ID^2 = sigma_v^2 mean_t |c_t|^2 / dt^2   the acceleration estimate's noise (c_t the weights
///                                           of the one window w of every coordinate at sample t's
///                                           place in it, off-centre at an episode's ends, where they
///                                           are larger; w the widest of the coordinates' own choices,
///                                           accelerations.hpp; the estimate has no bias against the
///                                           window's mean acceleration, which is what the filtered
///                                           residual compares),
///                + mean_t a_s,t^2           what the filter smears,
///                + mean_t a_h,t^2           what the data cannot tell about the controls' hold,
///                + |m|^2 mean_t |b_v o sigma_u|^2   and the controls' noise seen through the filter
///                                           (when the accelerations come from the measured positions,
///                                           accelerations.hpp, sigma_q^2 mean_t |c_t|^2 / dt^4 for the
///                                           first term, sigma_q the positions' noise);
///       a_s,t  = sum_r m_r f_v,r - W_v(x_t) sum_r m_r W_v(x_r)^-1 f_v,r,  f_v,r = f_v(x_r, u_r):
///                                           the window's mean of the model's acceleration against the
///                                           window's mean of its generalised force seen through the
///                                           inertia at x_t. This is the residual the filtered criterion
///                                           (criteria/inverse_dynamics.hpp: M(q_t) qdd_t - sum_r m_r g_r)
///                                           leaves on a true model, in acceleration units: zero while
///                                           the inertia does not change over the window, however
///                                           sharply the forces do (a Coulomb friction's switch, a
///                                           control's step), since both sides are the same window's
///                                           mean;
///       a_h,t  = b_v(x_t) ((m - m_0) * u)_t,  m and m_0 the weights of acceleration_weights for a
///                                           continuous control and for one held over each step, at
///                                           the window's centre.
///
///     The inverse-dynamics residual sees the controls through the weights the acceleration estimate
///     puts on the accelerations (parallel filtering, accelerations.hpp), so a control that changes
///     within the window costs nothing as long as the inertia barely changes over it (a_s) and the
///     control is the signal the weights assume (a_h: the filter assumes a continuous one, measured
///     torques; a command held over each step differs from that by half a sample at every change).
///     sigma_v is estimated from the velocity column itself and a_s, a_h from the model at the
///     measured states, so rho depends on the noise, the sampling rate and the motion only through
///     the data. On the two-link arm at 1 kHz with smooth measured torques rho = 17.7, and the actual
///     ratio of the two residuals' errors under the true model (the criterion's residual, filtered as
///     it filters) is 20.5; the same arm with a Coulomb friction that switches within 0.03 rad/s in the
///     model and the data, 22.4 (actual 18.1); with the torques held for 20 ms rho = 2.24 (actual
///     2.05); the cart-pole test data (50 Hz, held 5 samples) give 0.21; the cart-pole loop's
///     rollouts of 16 samples at 20 Hz, where most samples lie within a window of an end, 2.81
///     (tests/experiments/criterion_choice_test.cpp, loop_diagnosis_test.cpp). On the two-link arm's
///     50 Hz command-line data (held commands, a window of 173 samples of the 200 of an episode) rho
///     is 3.38 (actual 3.63), all of it the arm's inertia changing over the window, which is no noise:
///     kappa = 0.077 and eps = 0.14 keep one-step there (with inverse dynamics the unchanged model was
///     "explained" by a forearm 30% lighter, mujoco_cli_test.cpp).
///
///     kappa, per velocity state v, the smallest over them, at the window w above:
///
///       kappa^2 = (mean_t (sum_r m_r v_r - vbar)^2 - sigma_v^2 mean_t |m|^2) / (mean_t (v_t - vbar)^2 - sigma_v^2)
///
///     (vbar the episode's mean velocity, sigma_v the robust noise level above, whose share the window's
///     mean removes and which is no motion): how much of the motion the window's mean keeps. The
///     criterion compares the window's means of both sides of the equation (parallel filtering), so an
///     effect's regressor is its window's mean too (a viscous friction's is sum_r m_r v_r): what the
///     window averages away is neither fitted nor scored, and a window as long as the motion leaves
///     equations whose signal is mostly gone, against which the rest (the noise, the smear and the
///     hold above) is large. The velocity, not the acceleration: a sharp friction's switch is a step
///     in the acceleration that the window smooths without losing what the equation holds of it.
///     IDIM sets its filters' cutoff well above the bandwidth of the motion (Gautier 1997); kappa >=
///     0.9 asks the window to keep 90% of the motion's rms, for a uniform window's mean of a sinusoid
///     (sin x / x = 0.9 at x = 0.79 = pi f T) a window of a quarter of its period. Measured: at least
///     0.956 on the 1 kHz two-link arm's cases above, 0.995 on the 7-joint stand-ins (145 samples at
///     1 kHz), 0.994 on the Staubli TX40 (431 samples at 1 kHz; also on the model the defaults write,
///     whose sharp Coulomb friction on joint 4 keeps only 88% of the acceleration), 1.0 on the light
///     drive; 0.077 and 0.118 on the two-link arm's 50 Hz command-line data without and with an elbow
///     damping of 0.35 N m s (173 samples of the 200 of an episode). With the damping rho = 26 and eps
///     = 0.023 would take inverse dynamics, which fitted the damping as 0.69 N m s, twice its value
///     (criterion_choice_test.cpp, mujoco_cli_test.cpp).
///
///     eps, per velocity state v, the largest over them, at the window w above:
///
///       eps^2 = (mean_t a_s,t^2 + mean_t a_h,t^2) / mean_t |b_v(x_t) u_t|^2
///
///     the residual the filtered criterion leaves on a true model (what the filter smears, what the
///     data cannot tell about the controls' hold) against the force the controls apply, both in
///     acceleration units. This residual is systematic, not noise: least squares can put it into any
///     candidate effect it correlates with, by up to eps of the applied force, and the instruments do
///     not remove it. eps <= 0.03 (eps^2 <= 0.1% of the applied force's variance) bounds that bias at 3%
///     of the force. eps does not depend on the noise, which the filter and the instruments deal
///     with, but on how fast the data are sampled against the motion and the controls' changes.
///     Measured (tests/support/ball_drive.hpp, tests/experiments/duffing_diagnosis_test.cpp), with
///     the accelerations from the measured positions (accelerations.hpp): 0.0088 and 0.0083 on the
///     heavy and light stand-in drives at 1 kHz (the controls' hold, a command that jitters with the
///     encoder's counts: a carriage's inertia does not change), where inverse dynamics finds all three
///     true effects; 0.031 on the Duffing stand-in (100 Hz, the command held over each step: all of it
///     the hold), where the instrumental-variable form finds the cubic spring beside an input delay of
///     half a step, which is the hold; 0.096 on an imported cart-pole log (criterion_choice_test.cpp);
///     0.39 on the Silverbox at 610 Hz (a 70 Hz resonance: 9 samples a period). With measured
///     velocities: 0.0077 on the two-link arm with smooth torques, 0.005 with the sharp Coulomb
///     friction, 0.091 with velocity noise of 0.5 rad/s (a window of 85 samples) and 0.011 at a
///     quarter of its torques and noise.
///
///     Why 3: the pure noise ratio of the shortest window (w = 3) is sqrt(2) / (dt G(3)) = 2, so rho >= 3
///     needs a longer window, i.e. a signal smooth over several samples; and a factor 3 in error
///     (9 in variance) keeps the choice from flipping on the estimates of sigma_v and R_hat, which are
///     good to tens of percent. Below it one-step is kept: it needs no acceleration estimate and
///     integrates held controls exactly. The input delay of the model is not applied here: it shifts
///     the controls, not their smoothness.
///
///     Its instrumental-variable form (IDIM-IV, instrumental_variables.hpp) when some velocity was
///     estimated from other states (its noise is filtered and correlated, so the white-noise bound
///     below does not hold; the instruments, the model simulated with the measured controls, do not
///     share it), or, for measured velocities, when least squares on the force residual would be biased by the noise of the
///     measured velocities by 1% or more (lambda >= kInstrumentAttenuation): a friction linear in a
///     velocity v, fitted by least squares
///     on the measured v + e, shrinks by the factor var(v) / (var(v) + sigma_v^2), so by
///
///       lambda = max over the velocity states of sigma_v^2 / var(v_measured)
///
///     to first order (sigma_v the robust noise level above, var over every sample). 1% is an accuracy
///     below which published friction values do not go; a smaller bias is left to least squares, which
///     needs no simulation of the model and has the smaller variance.
///
///  3. Simulation when some state was estimated from others and rule 2 does not hold. A
///     one-step fit regresses on the measured state: when the velocities are filtered estimates, their
///     errors are errors in the variables and bias the fit (friction comes out too small, a motor's
///     gain below 1), which the simulation from an estimated start does not suffer within a window.
///     Output error is the second choice on a driven system: in a closed loop the controls depend on
///     the past noise, which biases a simulation error whose noise model is white (the direct method
///     of closed-loop identification, Forssell and Ljung 1999), while the instrumental-variable form
///     of the inverse-dynamics residual, whose instruments hold no noise of the rows they instrument,
///     is not (the purpose of IDIM-IV, Janot, Vandanjon and Gautier 2014).
///
///  4. One-step otherwise.
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
///    than every episode sets W to the cap;
///  - a velocity `<q>_dot` estimated from its position (MeasurementSet::estimated_states) is timed on
///    `<q>`: the derivative filter's noise is correlated over its window, which the hysteresis band
///    (from the column's differences) does not see, while the position carries the sensor's white
///    noise and the same oscillation. A position that drifts (no period within the episodes) leaves
///    the velocity's own period.
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
/// eps at or below which estimated velocities take inverse dynamics (file comment).
inline constexpr double kFilterMisfit = 0.03;
/// kappa at or above which the acceleration window keeps the motion (file comment).
inline constexpr double kMotionKept = 0.9;
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
  /// Why the controls are not generalised forces; empty when they are or when not asked (passive).
  std::string not_forces;
  bool forces_checked = false;                ///< rule 2 was reached
  double ratio = 0.0;                         ///< rho = min over velocity states of E_1 / E_ID (0: not measured)
  std::string ratio_state;                    ///< the velocity state of the minimum
  int acceleration_window = 0;                ///< its derivative window w [samples]
  int acceleration_derivative = 1;            ///< 1: of the velocities; 2: of the measured positions (accelerations.hpp)
  double control_error = 0.0;                 ///< sqrt(mean a_h^2) / E_ID there: the hold's share
  double smear_error = 0.0;                   ///< sqrt(mean a_s^2) / E_ID there: the motion's share
  double misfit = 0.0;                        ///< eps = max over velocity states (0: not measured)
  std::string misfit_state;                   ///< the velocity state of the maximum
  double motion_kept = 0.0;                   ///< kappa = min over velocity states (0: not measured)
  std::string motion_kept_state;              ///< the velocity state of the minimum
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
