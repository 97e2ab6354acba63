#pragma once
/// @file effect_fit.hpp
/// Which physical effect is missing: fit every effect of the library to the one-step residuals of the
/// training episodes and score it on the held-out episodes, under the context's criterion
/// (criteria/criterion.hpp). Under the simulation criterion phi(x_t, u_t; theta) below stands for the
/// model simulated from the start of t's window, and every step is otherwise the same.
///
/// For an effect with parameters theta (current value theta_0 in the model) the predicted next state
/// is phi(x_t, u_t; theta) (the model with the effect, integrated like the model). With per-state
/// weights w_i = 1 / sigma_i^2 (sigma_i the noise floor) the fit minimises
///
///   S(theta) = sum_{t in training} sum_i w_i (x_{t+1,i} - phi_i(x_t, u_t; theta))^2.
///
/// 1. Linear least squares on the regressor J = d phi / d theta at theta_0 (central differences of the
///    step, step 1e-4 of the parameter's scale): theta_LS = theta_0 + argmin |W^1/2 (r - J d)|^2, r the
///    model's residual. For an effect linear in theta (friction, drag, external forces, the gain, kv,
///    km, rho) this is the estimate up to the RK4 discretisation; for the others it is a Gauss-Newton
///    step.
/// 2. Gauss-Newton on S from theta_0, each step clamped to the parameters' physical range and halved
///    until S falls: two steps for effects linear in theta (the first is step 1's), up to twelve for
///    the others and for every effect under the simulation criterion (its prediction over a window
///    is not linear in theta); this gives the final estimate theta_hat. (A derivative-free search took 30 to 200
///    evaluations of S per parameter; on 25,000 samples of a MuJoCo model that was most of the time.)
/// 3. A 95% interval from the Gauss-Newton covariance at theta_hat, s^2 (J'WJ)^-1 with
///    s^2 = S / (m - p), m the equations that are not 0 = 0 (N n, less those a criterion leaves out),
///    widened to the delete-one-episode jackknife when that is larger (over the episodes that hold an
///    equation): one-step residuals of one episode are correlated, so the iid interval alone is too narrow. The quantile
///    is 1.96 for the Gauss-Newton variance and Student's t_{0.975, R - 1} for a jackknife of R
///    replicates (student_t.hpp).
/// 4. On the held-out episodes: RMSE per state before and after, and the weighted fraction of
///    squared residual explained, 1 - S_after / S_before, with a 95% interval and a z score from batch
///    means of the per-sample reduction (batches of consecutive samples within an episode, so the
///    serial correlation of the residual does not inflate the significance): with K batches, Student's
///    quantile on K - 1 degrees of freedom and z the normal equivalent of the studentised mean. The
///    batches are kept per channel, so the same share can be taken on some channels only
///    (heldout_share): an effect is judged on the channels it acts on (effect_test.hpp, test 3).
///
/// Inverse dynamics (FitCriterion::InverseDynamics). A force effect enters the generalised-force
/// residual as r(theta) = r^0 - Q_e(theta), so for forces linear in their parameters the residual is
/// affine, r(theta) = r(theta_0) - G (theta - theta_0), and J = sqrt(w) G is their forces' bases
/// (affine_force_residual.hpp): a set of such forces is fitted without rebuilding the model (one
/// evaluation of its residual, then matrix products; step 2 converges at its first step), and in a set
/// with other effects their columns of J are exact while the others' are differences.
///
/// Joint fits. Effects already in a model are refitted together with a new one: theta stacks the
/// parameters of every effect of the set, [theta_1; ...; theta_E], and steps 1-4 run on the stacked
/// vector (the regressor has one column per parameter, the interval comes from the joint covariance,
/// so it accounts for the correlation between the effects). Forward selection (effect_selection.hpp)
/// and `--add` use them.
///
/// Aliases: two effects that a joint fit cannot separate on these data (rank_effects) are reported
/// as one group under the best of them.

#include <functional>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/experiments/diagnosis/criteria/criterion.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"

namespace gpilqg::diagnosis {

/// The data and model a fit works on. The criterion's channels are the states (one-step, simulation)
/// or the generalised-force components (inverse dynamics): c of them below.
struct FitContext {
  const Transitions* data = nullptr;
  ModelSpec model;                      ///< the model the effect is added to
  Integrator integrator = Integrator::RK4;
  double dt = 0.02;
  int substeps = 1;
  Vector weights;                       ///< c, w_i = 1 / sigma_i^2
  Matrix residual;                      ///< N x c, the model's residual at every row (under the criterion)
  /// Batch length of the held-out significance test; 0: ceil(sqrt(N)) of the N held-out rows, at
  /// least 10 (24 on 600 held-out rows, 87 on 7,500). criterion_context makes it at least a window.
  int batch = 0;
  /// The criterion the residual, the fits and the scores are under (criteria/criterion.hpp): made
  /// for these data and this model by criterion_context; one-step by default.
  std::shared_ptr<const Criterion> criterion = one_step_criterion();
  /// Simulation: whether criterion_context estimates the windows' starts; false:
  /// every window from its measured start, as simulated_predictions runs it.
  bool estimate_starts = true;
  /// Candidates left out of every ranking and search (`--exclude`): effects the user declares
  /// physically meaningless for these data (an armature when torques are measured after the gearbox).
  std::vector<std::string> excluded = {};
  /// Inverse dynamics: fit a set with parameters of the model (a mass, an armature) in the closed form
  /// of affine_force_residual.hpp when the data show its residual to be affine in them (effect_fit.cpp
  /// probes it, and checks it again at the estimate). False: the rebuilt model at every theta, the
  /// general path, which gives the same fit to rounding where the closed form holds.
  bool probe_affine = true;
  /// Evaluations of the model one fit runs at once (its regressor's columns by differences, the
  /// probes of the closed form): set by the searches to the threads their own loops leave idle.
  int threads = 1;
};

/// The model integrated as configured.
std::shared_ptr<const StepModel> make_step_model(const ModelSpec& model, Integrator integrator, double dt, int substeps);

/// settings.criterion->predictions: the next state predicted at every row of settings.data (N x n).
Matrix model_predictions(const ModelSpec& model, const FitContext& settings, int* diverged = nullptr);

/// settings.criterion->weighted_residual: sqrt(w_i) r_{t,i} of `model` stacked over `rows`.
Vector weighted_residual_of(const ModelSpec& model, const FitContext& settings, const std::vector<int>& rows);

/// settings.criterion->residual: the residual of `model` at every row of settings.data (N x c).
Matrix criterion_residual(const ModelSpec& model, const FitContext& settings, int* diverged = nullptr);

/// The values of one effect inside a joint fit: where it started, where it ended, its 95% interval.
struct EffectValues {
  std::string effect;
  std::vector<EffectParameter> parameters;
  Vector initial;          ///< the start of the fit
  Vector estimate;         ///< the joint estimate
  Vector ci_low, ci_high;  ///< 95% interval from the joint covariance
  double smoothing = 0.0;  ///< Coulomb friction: its smoothing velocity v0 (LibraryEffect::smoothing); else 0
  /// The value without the effect: its value in the model it is added to (a force 0, a gain 1, the
  /// model's parameter, no delay); the null hypothesis of its interval test (effect_test.hpp).
  Vector null_value = {};
  /// The criterion's channels it acts on (EffectFit::acts_on).
  std::vector<int> acts_on = {};
};

struct EffectFit {
  std::string effect;
  std::vector<EffectParameter> parameters;
  Vector initial;            ///< theta_0
  Vector linear_estimate;    ///< theta_LS
  Vector estimate;           ///< theta_hat (NLopt)
  Vector ci_low, ci_high;    ///< 95% interval of theta_hat (infinite when the covariance is not finite)
  double smoothing = 0.0;    ///< Coulomb friction: its smoothing velocity v0 (LibraryEffect::smoothing); else 0
  /// The value without the effect, in the model it is added to (EffectValues::null_value).
  Vector null_value;
  /// Each parameter's scale on these data: max(|null_value_j|, |m| / |J_j|), with m the model's own
  /// weighted predicted change of the velocities over the training rows and J_j the weighted
  /// regressor of parameter j on the same rows: the change of theta_j that moves the predictions as
  /// much as the model itself moves them. A force is then measured against the forces the model
  /// applies, an armature against the joint's inertia, a mass against the mass. A parameter further
  /// than kRunawayFactor times this from null_value is not identifiable (effect_test.hpp).
  Vector scale;
  int evaluations = 0;       ///< evaluations of the residual in step 2
  double training_objective_before = 0.0;  ///< S(theta_0)
  double training_objective_after = 0.0;   ///< S(theta_hat)
  Vector heldout_rmse_before;  ///< n
  Vector heldout_rmse_after;   ///< n
  double explained = 0.0;      ///< 1 - S_after / S_before on the held-out rows
  double explained_ci = 0.0;   ///< half-width of its 95% interval
  double z_score = 0.0;        ///< normal equivalent of mean reduction / its batch-means standard error
  /// The held-out batches of the significance test (step 4), in order: each batch's weighted
  /// squared residual of the model (before) and its reduction by the fit (before - after). Every fit
  /// of one context has the same batches, so two fits can be compared batch by batch
  /// (effect_test.hpp, compare_heldout).
  Vector heldout_batch_before, heldout_batch_reduction;
  /// The same batches per channel (K x c); the two vectors above are their row sums.
  Matrix heldout_channel_before, heldout_channel_reduction;
  /// The criterion's channels this effect acts on: those where its columns of the weighted regressor
  /// over the training rows are not zero (above 1e-12 of the largest channel's squared sum). Under
  /// inverse dynamics a joint's friction acts on its own joint's torque only; under the one-step and
  /// simulation criteria a force usually acts on every state through the inverse inertia.
  std::vector<int> acts_on;
  Vector regressor;            ///< weighted J at theta_0 over the training rows (first parameter), for aliasing
  /// False when the data do not determine the fit: the effect does not change the predictions, its
  /// covariance is not finite, or a parameter of the set ran away (effect_test.hpp, test 1).
  bool identifiable = true;
  std::string not_identifiable;  ///< why, in one clause, when !identifiable
  /// Effects refitted jointly with this one (fit_jointly), with their new values; empty for a fit of
  /// one effect alone. The scores above (objective, held-out RMSE, explained) are those of the set.
  std::vector<EffectValues> refitted;
};

/// A share of the held-out residual that a fit removes, with its 95% half-width and z score (step 4).
struct HeldoutShare {
  double explained = 0.0;
  double explained_ci = 0.0;
  double z_score = 0.0;
};

/// Step 4's share on the channels `channels` of the criterion (all of them when empty): the ratio
/// estimator R = D / B of the batches' reductions and "before" terms summed over those channels, with
/// Var(R) ~ K / (K - 1) sum_b (d_b - R b_b)^2 / B^2 and Student's quantile on K - 1 degrees of freedom.
/// On every channel it is the fit's own explained, explained_ci and z_score. K counts the batches
/// that hold an equation (batches_with_equations).
HeldoutShare heldout_share(const EffectFit& fit, const std::vector<int>& channels);

/// The batches (before b_k, reduction d_k) that hold at least one equation of the criterion: those
/// with b_k > 0 or d_k != 0. A batch whose every residual is zero before and after, whatever the
/// model, has only equations a criterion leaves out (a coordinate at standstill under inverse
/// dynamics, InverseDynamicsCriterion): it adds nothing to the sums B and D and is no batch of the
/// variance's K.
std::pair<Vector, Vector> batches_with_equations(const Vector& before, const Vector& reduction);

/// `fit` with the values of `values` (one effect of its joint fit) as its own effect's: its name,
/// parameters, start, estimate, interval and smoothing; the scores stay those of the joint fit.
EffectFit led_by(EffectFit fit, const EffectValues& values);

/// The values of `fit`'s own effect, as one entry of a joint fit.
EffectValues own_values(const EffectFit& fit);

/// The central-difference step of parameter j of theta (spec its parameter): theta -+ h e_j with
/// h = 1e-4 max(|theta_j|, spec.scale), each point kept within the physical range [lower, upper]
/// (one-sided, theta itself, when theta sits on a bound: an input delay fitted to its largest value
/// is probed below it, never beyond). The derivative is (f(plus) - f(minus)) / width, and 0 when the
/// range is the single point theta_j (width 0: a parameter that cannot move).
struct DifferenceStep {
  Vector minus, plus;
  double width = 0.0;
  /// 1 / width, 0 when the width is 0: the derivative is (f(plus) - f(minus)) * inverse_width().
  double inverse_width() const { return width > 0.0 ? 1.0 / width : 0.0; }
};
DifferenceStep difference_step(const EffectParameter& spec, const Vector& theta, Eigen::Index j);

/// Fits one effect (steps 1-4 above). Never returns NaN: an effect without influence on the data
/// (J = 0) keeps theta_0, identifiable = false and explained = 0.
EffectFit fit_effect(const LibraryEffect& effect, const FitContext& context);

/// An effect already in the model, refitted jointly with the candidate, from the value `start`.
struct RefitEffect {
  const LibraryEffect* effect = nullptr;
  Vector start;
};

/// Fits `effect` jointly with the effects of `refit` (steps 1-4 on the stacked parameters; see the
/// file comment): the model is context.model with every effect of the set at its values, the
/// candidate starting from `start` (its current value in context.model when empty). The held-out
/// scores compare the fitted set with context.residual, so with a context whose residual is that of
/// the model with `refit` at their starts they measure what adding `effect` (and refitting the rest)
/// gains. Each effect may appear once. Never returns NaN.
EffectFit fit_jointly(const LibraryEffect& effect, const std::vector<RefitEffect>& refit, const FitContext& context,
                      const Vector& start = {});

/// Scores the effect at given values without fitting (step 4 only): estimate = linear_estimate =
/// ci_low = ci_high = values. Throws std::invalid_argument for values the effect does not accept.
EffectFit score_effect(const LibraryEffect& effect, const VectorCRef& values, const FitContext& context);


/// One entry of the ranking: the best effect of an alias group and the others of the group.
struct RankedEffect {
  EffectFit fit;
  std::vector<EffectFit> aliases;
  /// This entry against the ranking's first (compare_heldout, effect_test.hpp): its held-out share
  /// minus the first's, with the 95% half-width of that paired difference; both 0 for the first.
  double behind_first = 0.0, behind_first_ci = 0.0;
  /// True when the held-out rows do not prefer the first entry to this one (the paired difference is
  /// within its 95% interval) although the two are not aliases: a rival explanation.
  bool rival = false;
};

/// Fits every candidate effect and ranks the alias groups in the order of their standing
/// (effect_test.hpp): the identifiable fits whose 95% interval excludes their value without them, then
/// the identifiable ones whose interval holds it, each in the order of their cross-validated screening
/// score on the training rows (LinearisedFits::screening_left; the held-out rows score the entries,
/// they do not choose among them), then, unranked and
/// in no alias group, the fits that are not identifiable (EffectFit::identifiable). Two effects
/// are aliases when their joint fit cannot separate them: the pair, fitted together on the training
/// rows, removes less than `alias_gain` of the held-out residual that either leaves alone (each alone
/// does what both do; linearised_fits.hpp), or the system declares them the same physics. Grouping is
/// greedy: the best remaining effect takes every remaining effect that is its alias.
/// `progress` (optional) receives one line per fitted effect and may throw to stop the ranking.
/// `refit` (forward selection): effects already chosen, refitted jointly with every candidate
/// (fit_jointly); they and their declared aliases are not candidates. `threads` candidates are
/// fitted at once.
std::vector<RankedEffect> rank_effects(const FitContext& context, double alias_gain = 0.05,
                                       const std::function<void(const std::string&)>& progress = {},
                                       const std::vector<RefitEffect>& refit = {}, int threads = 1);

}  // namespace gpilqg::diagnosis
