#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/input_delay.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/experiments/diagnosis/criteria/criterion_context.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/criterion_choice.hpp"
#include "gpilqg/experiments/diagnosis/data_problem.hpp"
#include "gpilqg/experiments/diagnosis/effect_selection.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/generalised_force_residual.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"
#include "gpilqg/experiments/diagnosis/velocity_scales.hpp"

namespace gpilqg::diagnosis {

void DiagnosisOptions::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("diagnosis option " + what);
  };
  require(substeps >= 1, "'substeps' must be >= 1");
  require(heldout_fraction > 0.0 && heldout_fraction < 1.0, "'heldout_fraction' must be in (0, 1)");
  for (int k : horizons) require(k >= 1, "'horizons' must be >= 1");
  std::vector<int> sorted = horizons;
  std::sort(sorted.begin(), sorted.end());
  require(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end(), "'horizons' must be distinct");
  require(gp.points >= 10, "'gp.points' must be >= 10");
  require(gp.restarts >= 0 && gp.threads >= 1, "'gp.restarts' must be >= 0 and 'gp.threads' >= 1");
  require(bins >= 1 && max_lag >= 0, "'bins' must be >= 1 and 'max_lag' >= 0");
  require(alias_gain >= 0.0 && alias_gain < 1.0, "'alias_gain' must be in [0, 1)");
  require(max_subset >= 1 && max_subset <= 6, "'max_subset' must be in 1..6");
  require(explained_left_ratio >= 1.0, "'explained_left_ratio' must be >= 1");
  require(structure_threshold >= 0.0 && floor_tolerance >= 1.0, "'structure_threshold' >= 0, 'floor_tolerance' >= 1");
  require(min_explained >= 0.0 && min_step_explained >= 0.0 && min_z >= 0.0 && relative_to_gp >= 0.0,
          "thresholds must be >= 0");
  require(window >= 1 && (criterion == FitCriterion::Simulation || window == 1),
          "'window' must be >= 1, and 1 with the one-step criterion");
}

namespace {

Matrix residual_of(const Transitions& data, const Matrix& predicted) { return data.x_next - predicted; }

Vector heldout_rmse(const Transitions& data, const Matrix& residual) {
  const std::vector<int> rows = data.rows(true);
  Vector out(residual.cols());
  for (Eigen::Index i = 0; i < residual.cols(); ++i) out(i) = rms(residual.col(i), rows);
  return out;
}

/// The noise floor per state: the held-out RMSE of the best predictor at hand, the model or the model
/// corrected by the GP, min(RMSE(r), RMSE(r - mu)) on the held-out episodes. It is the error that neither
/// the model nor a flexible function of (x, u) fitted on other episodes can remove. (The GP's own noise
/// std sn is reported too, but maximum likelihood can trade it for a very short length-scale and then
/// it says nothing; the cross-validated floor cannot be fooled that way.) Kept above 1e-12 (1 + RMSE) so
/// that weights stay finite on noise-free data.
Vector noise_floor(const Transitions& data, const Matrix& residual, const ResidualGp& gp) {
  const Vector model = heldout_rmse(data, residual);
  const Vector corrected = heldout_rmse(data, residual - gp.mean);
  return model.cwiseMin(corrected).cwiseMax(1e-12 * (1.0 + model.array()).matrix());
}

/// w_i = 1 / floor_i^2.
Vector floor_weights(const Transitions& data, const Matrix& residual, const ResidualGp& gp) {
  return noise_floor(data, residual, gp).cwiseAbs2().cwiseInverse();
}

/// Rows normalised to sum 1 (rows of zeros stay zero).
Matrix shares(Matrix sensitivity) {
  for (Eigen::Index i = 0; i < sensitivity.rows(); ++i) {
    const double total = sensitivity.row(i).sum();
    if (total > 0.0) sensitivity.row(i) /= total;
  }
  return sensitivity;
}

/// The single-effect verdict on the ranking. `in_model`: the model's own effects that each fit of
/// the ranking refits beside its candidate (--auto), which are not findings of their own: their
/// intervals and channels are not judged (effect_test.hpp), as in the search.
Verdict decide(const DiagnosisReport& r, const DiagnosisOptions& o, const std::vector<std::string>& in_model) {
  Verdict v;
  if (r.model_diverges) {
    v.status = "model_diverges";
    v.reason = fmt::format("the model diverges (a predicted state not finite or beyond |x| = {:g}) on {} of {} one-step "
                           "transitions and {} of {} k-step windows started from measured states, which stay within "
                           "the bound: fix the model (its parameters, dt, integrator) before looking for a missing effect",
                           kDivergedStateMagnitude, r.non_finite_predictions, r.samples, r.diverged_windows, r.windows);
    return v;
  }
  if (r.consistent) {
    v.status = "consistent";
    v.reason = "every state's held-out residual is at its noise floor: there is nothing left to explain";
    return v;
  }
  if (r.ranking.empty()) {
    v.status = "unexplained";
    v.reason = "the residual is structured and no effect was ranked";
    return v;
  }
  const RankedEffect& best = r.ranking.front();
  const EffectFit& f = best.fit;
  const EffectTestResult finding = test_effect(f, {o.min_explained, o.min_z}, in_model);
  v.left = 1.0 - f.explained;
  v.gp_left = 1.0 - r.gp_explained_total;
  v.reason = fmt::format("the best candidate '{}' removes {:.1f}% of the held-out residual (z = {:.1f}); the GP removes {:.1f}%",
                         f.effect, 100.0 * f.explained, f.z_score, 100.0 * r.gp_explained_total);
  // The GP's share is of the one-step residual: comparable with the effects' under the one-step criterion only.
  const bool one_step = r.criterion->scored_like_the_gp();
  if (!one_step)
    v.reason += " of the one-step residual; the effects are scored on " + r.criterion->scored_on() +
                ", so the GP's share is not required";
  if (!finding.accepted) {
    v.status = "unexplained";
    v.reason += "; not a finding: " + finding.reason;
    return v;
  }
  // With --auto the rule is the chosen set's (judge_selection): several effects may together remove
  // what the GP removes when none does alone.
  if (one_step && !o.auto_select && f.explained < o.relative_to_gp * r.gp_explained_total) {
    v.status = "unexplained";
    v.reason += ", so the residual's structure is mostly something else";
    return v;
  }
  v.effect = f;
  for (const auto& a : best.aliases) v.aliases.push_back(a.effect);
  for (const RankedEffect& other : r.ranking)
    if (other.rival) v.rivals.push_back(other.fit.effect);
  // "explained" until the remainder test (judge_remainder) has seen what the effect leaves.
  v.status = "explained";
  return v;
}

/// The remainder test, the same for every criterion: "explained" or "partly_explained" from what a
/// flexible model finds in what the proposed effects leave. The flexible model is the model with the
/// effects plus a GP of its one-step residual (fitted on the training episodes); `remainder` is the
/// share of the effects' weighted held-out error (under the criterion) that it removes. A wrong effect
/// can remove much of a residual (a Coulomb term alone takes 90% of what viscous friction, Coulomb
/// friction and a constant force do together); what it leaves then still has structure, which the
/// GP of its remainder finds. "explained" when the effects leave at most explained_left_ratio (1.5)
/// times what the flexible model leaves, i.e. remainder <= 1 - 1 / 1.5 = 1/3. Unlike a comparison
/// with the GP of the model without the effects, this cannot pass by default when that GP explains
/// little: the GP is fitted to what the effects leave.
void judge_remainder(Verdict& v, double remainder, const DiagnosisOptions& o) {
  if (!v.effect || v.status != "explained") return;
  v.remainder = remainder;
  const double allowed = 1.0 - 1.0 / o.explained_left_ratio;
  // A flexible model that predicts worse than the effects (its GP-corrected simulation drifts off)
  // finds no structure in what they leave: nothing to remove, whatever it adds.
  v.reason += fmt::format("; the GP of what {} leave{} {}", v.effects.size() > 1 ? "the effects" : "the effect",
                          v.effects.size() > 1 ? "" : "s",
                          remainder >= 0.0 ? fmt::format("removes {:.1f}% of it", 100.0 * remainder)
                                           : std::string("removes nothing of it (its predictions are worse)"));
  if (remainder <= allowed) return;
  v.status = "partly_explained";
  v.reason += fmt::format(" (at most {:.1f}% for \"explained\": what is left is at most {:g} times what a flexible model "
                          "leaves), so the data reject the model with {} alone; its interval assumes that model",
                          100.0 * allowed, o.explained_left_ratio,
                          v.effects.size() > 1 ? std::string("these effects") : std::string("this effect"));
}

/// The verdict once --auto has chosen its set: what the whole set leaves (each step's share is of
/// what the step before left, so the shares multiply).
void judge_selection(Verdict& v, const Selection& selection, const ModelSpec& m0, const Criterion& criterion,
                     const DiagnosisOptions& o) {
  if (!v.effect) return;
  if (selection.steps.empty()) {
    // Nothing chosen: the single best effect meets the rule decide() left to the set.
    if (criterion.scored_like_the_gp() && v.effect->explained < o.relative_to_gp * (1.0 - v.gp_left)) {
      v.status = "unexplained";
      v.reason += ", so the residual's structure is mostly something else";
      v.effect.reset();
      v.aliases.clear();
      v.rivals.clear();
    }
    return;
  }
  double left = 1.0;
  for (const SelectionStep& step : selection.steps) left *= 1.0 - step.fit.explained;
  v.left = left;
  // The last step's joint fit holds every chosen effect; those M_0 had are not new.
  const std::vector<LibraryEffect> candidates = candidate_effects(m0);
  const std::vector<RefitEffect> had = model_effects(m0, candidates);
  const auto is_new = [&](const std::string& name) {
    return std::none_of(had.begin(), had.end(), [&](const RefitEffect& r) { return r.effect->name == name; });
  };
  const EffectFit& last = selection.steps.back().fit;
  v.effects.clear();
  if (is_new(last.effect)) v.effects.push_back(last.effect);
  for (const EffectValues& e : last.refitted)
    if (is_new(e.effect)) v.effects.push_back(e.effect);
  // The verdict is the set's: its values and intervals are those of the set's joint fit, and the
  // single effect's aliases are not the set's.
  v.effect = last;
  v.aliases.clear();
  // A set of one is the ranking's first: its rivals stand (judge); a larger set has none computed.
  if (!(v.effects.size() == 1 && last.refitted.empty() && v.effects.front() == last.effect)) v.rivals.clear();
  v.reason = fmt::format("the {} effect(s) chosen by --auto ({}) remove {:.1f}% of the held-out residual; the GP removes {:.1f}%",
                         v.effects.size(), fmt::join(v.effects, ", "), 100.0 * (1.0 - left), 100.0 * (1.0 - v.gp_left));
  if (!criterion.scored_like_the_gp())
    v.reason += " of the one-step residual (the effects are scored on " + criterion.scored_on() + ")";
  if (criterion.scored_like_the_gp() && 1.0 - left < o.relative_to_gp * (1.0 - v.gp_left)) {
    v.status = "partly_explained";
    v.reason += fmt::format(", less than {:g} of what the GP removes, so the residual's structure is mostly something else",
                            o.relative_to_gp);
  }
}

/// The one-step residual of `model` on settings.data, integrated as `settings` says and driven by
/// the measured inputs as the model applies them (its input delay).
Matrix residual_of_model(const ModelSpec& model, const FitContext& settings) {
  return residual_of(*settings.data, model_predictions(model, settings));
}

/// The episodes every step below sees. One continuous record is cut into blocks with gaps that
/// become its episodes (heldout_blocks.hpp; stored in `blocks_as_episodes`); several episodes are
/// used as they are. Fills the report's names, dt, held-out episodes and transitions, and returns
/// the episodes (`blocks_as_episodes` or `input`).
const MeasurementSet& episodes_of(const MeasurementSet& input, const DiagnosisOptions& o,
                                  MeasurementSet& blocks_as_episodes, DiagnosisReport& R) {
  if (input.episodes.size() == 1) {
    const int gap = heldout_block_gap(o.horizons, o.window);
    R.blocks = split_heldout_blocks(input.episodes.front(), o.heldout_fraction, gap, kHeldoutBlockCount,
                                    gap == o.window && o.window > 1 ? "the simulation window" : "the longest k-step horizon");
    blocks_as_episodes = block_episodes(input, *R.blocks);
  }
  const MeasurementSet& set = R.blocks ? blocks_as_episodes : input;
  R.state_names = names_of(set.system.states);
  R.control_names = names_of(set.system.controls);
  R.input_names = R.state_names;
  R.input_names.insert(R.input_names.end(), R.control_names.begin(), R.control_names.end());
  R.dt = input.episodes.front().dt();
  R.heldout_episode_index = R.blocks ? R.blocks->heldout() : heldout_episodes(set, o.heldout_fraction);
  for (int i : R.heldout_episode_index) R.heldout_episode_ids.push_back(set.episodes[static_cast<std::size_t>(i)].id);
  R.data = make_transitions(set, R.heldout_episode_index, R.dt);
  R.samples = R.data.size();
  return set;
}

/// The model as given (o.model) against the data, before any effect is added.
struct ModelAsGiven {
  /// o.model with the smoothing velocity of its absent Coulomb candidates fitted to the data
  /// (velocity_scales.hpp): the report's model_before and the start of every fit below.
  ModelSpec model;
  std::shared_ptr<const StepModel> step;  ///< o.model as given, integrated as configured
  Matrix residual;                        ///< its one-step residual r_0 = x_next - f_0(x, u)
  ResidualGp gp;                          ///< the GP of r_0
  Vector weights;                         ///< 1 / floor_i^2 of r_0 and its GP (floor_weights)
};

/// The fit context of the options' criterion (criterion_context), with the instruments of the
/// inverse-dynamics criterion's IV form when it is asked for (instrumental_variables.hpp).
FitContext options_context(const DiagnosisOptions& o, const FitContext& base, int* restarts = nullptr) {
  FitContext context = criterion_context(base, o.criterion, o.window, restarts);
  if (const InverseDynamicsCriterion* inverse = context.criterion->inverse_dynamics(); inverse && o.instruments)
    context.criterion = inverse->with_instruments(context);
  return context;
}

ModelAsGiven model_as_given(const DiagnosisOptions& o, const FitContext& settings) {
  const Transitions& data = *settings.data;
  ModelAsGiven given;
  given.step = make_step_model(o.model, o.integrator, settings.dt, o.substeps);
  given.residual = residual_of_model(o.model, settings);
  given.gp = fit_residual_gp(given.step, data, given.residual, o.gp);
  if (o.progress) o.progress("residual GP of the model fitted");
  given.weights = floor_weights(data, given.residual, given.gp);
  // The Coulomb candidates' widths are fitted on the error every fit below is scored on: under
  // inverse dynamics the force residual, whose switch at qdot = 0 a one-step residual of velocity
  // increments at kilohertz rates hides in its noise. Least squares suffices for a width (the
  // instruments of the IV form remove a bias of the levels).
  const FitContext criterion = criterion_context(
      FitContext{&data, o.model, o.integrator, settings.dt, o.substeps, given.weights, given.residual}, o.criterion, o.window);
  given.model = with_fitted_smoothing(criterion);
  return given;
}

/// The --add effects on the model as given: those with given values first (kept as given, scored
/// under the criterion), then the others fitted jointly on the training episodes together with the
/// effects the model already has (refitted from their current values). Sets the report's model (the
/// diagnosed model: the model as given plus the added effects), added and refitted.
void add_requested_effects(const DiagnosisOptions& o, const ModelAsGiven& given,
                           const std::vector<LibraryEffect>& candidates, const FitContext& settings, DiagnosisReport& R) {
  const Transitions& data = R.data;
  R.model = given.model;
  Matrix residual = given.residual;
  std::vector<const LibraryEffect*> to_fit;
  std::vector<std::string> kept_as_given;
  for (const EffectRequest& request : o.add) {
    const LibraryEffect& effect = named(candidates, request.effect);
    if (!request.values) {
      to_fit.push_back(&effect);
      continue;
    }
    const FitContext context = options_context(o, {&data, R.model, o.integrator, R.dt, o.substeps, given.weights, residual});
    R.added.push_back(score_effect(effect, *request.values, context));
    R.model = R.model.with(effect, *request.values);
    residual = residual_of_model(R.model, settings);
    kept_as_given.push_back(effect.name);
  }
  if (to_fit.empty()) return;
  std::vector<RefitEffect> refit;
  for (std::size_t i = 1; i < to_fit.size(); ++i) refit.push_back({to_fit[i], R.model.current_values(*to_fit[i])});
  for (const RefitEffect& r : model_effects(R.model, candidates)) {
    const bool requested = std::find(to_fit.begin(), to_fit.end(), r.effect) != to_fit.end();
    const bool kept = std::find(kept_as_given.begin(), kept_as_given.end(), r.effect->name) != kept_as_given.end();
    if (!requested && !kept) refit.push_back(r);
  }
  const FitContext context = options_context(o, {&data, R.model, o.integrator, R.dt, o.substeps, given.weights, residual});
  const EffectFit joint = fit_jointly(*to_fit.front(), refit, context);
  R.model = R.model.with(*to_fit.front(), joint.estimate);
  for (const EffectValues& v : joint.refitted) R.model = R.model.with(named(candidates, v.effect), v.estimate);
  // One entry per requested effect, with the joint scores; the model's own effects as refitted values.
  EffectFit first = joint;
  first.refitted.clear();
  R.added.push_back(first);
  for (std::size_t i = 1; i < to_fit.size(); ++i) R.added.push_back(led_by(first, joint.refitted[i - 1]));
  R.refitted.assign(joint.refitted.begin() + static_cast<std::ptrdiff_t>(to_fit.size() - 1), joint.refitted.end());
}

/// The diagnosed model against the data: its one-step predictions and residual r, the GP of r (the
/// model as given's when nothing was added) and the weights w_i = 1 / floor_i^2. Returns the noise
/// floors (noise_floor).
Vector fit_diagnosed_residual(const DiagnosisOptions& o, const ModelAsGiven& given, const FitContext& settings,
                              const std::shared_ptr<const StepModel>& step, DiagnosisReport& R) {
  const Transitions& data = R.data;
  R.predicted = model_predictions(R.model, settings, &R.non_finite_predictions);
  R.residual = residual_of(data, R.predicted);
  R.gp = o.add.empty() ? given.gp : fit_residual_gp(step, data, R.residual, o.gp);
  const Vector floors = noise_floor(data, R.residual, R.gp);
  R.weights = floors.cwiseAbs2().cwiseInverse();
  return floors;
}

/// 1. Compare the diagnosed model with the measurements: per state the one-step RMSE, fit percent,
/// noise floor, the GP's held-out explained share and whether the residual is structured (the GP
/// explains more than structure_threshold and the held-out RMSE exceeds floor_tolerance times the
/// floor); per horizon k the k-step predictions from measured states, every max(1, k / 10) samples.
/// The model diverges when a one-step prediction or a k-step window does.
void compare(const DiagnosisOptions& o, const MeasurementSet& set, const StepModel& step, const Vector& floors,
             DiagnosisReport& R) {
  const Transitions& data = R.data;
  const int n = static_cast<int>(R.state_names.size());
  const Vector gp_structure = gp_explained(R.gp, data, R.residual);
  const Vector rmse_heldout = heldout_rmse(data, R.residual);
  for (int i = 0; i < n; ++i) {
    StateScore s;
    s.name = R.state_names[static_cast<std::size_t>(i)];
    s.rmse = rms(R.residual.col(i));
    s.fit_percent = fit_percent(data.x_next.col(i) - data.x.col(i), R.predicted.col(i) - data.x.col(i));
    s.noise_floor = floors(i);
    s.gp_noise_std = R.gp.noise_std(i);
    s.heldout_rmse = rmse_heldout(i);
    s.gp_explained = gp_structure(i);
    s.structured = s.gp_explained > o.structure_threshold && s.heldout_rmse > o.floor_tolerance * s.noise_floor;
    R.states.push_back(s);
  }
  std::vector<int> all_episodes(set.episodes.size());
  for (std::size_t e = 0; e < all_episodes.size(); ++e) all_episodes[e] = static_cast<int>(e);
  for (int k : o.horizons) {
    KStepScore score;
    score.k = k;
    score.stride = std::max(1, k / 10);
    score.predictions = k_step_predictions(step, set, all_episodes, k, score.stride, R.model.input_delay);
    score.windows = static_cast<int>(score.predictions.measured.rows());
    score.diverged = score.predictions.diverged;
    score.rmse = Vector::Zero(n);
    score.fit_percent = Vector::Zero(n);
    for (int i = 0; i < n && score.windows > 0; ++i) {
      const Vector e = score.predictions.measured.col(i) - score.predictions.predicted.col(i);
      score.rmse(i) = rms(e);
      score.fit_percent(i) = fit_percent(score.predictions.measured.col(i), score.predictions.predicted.col(i));
    }
    R.windows += score.windows + score.diverged;
    R.diverged_windows += score.diverged;
    R.k_step.push_back(std::move(score));
  }
  R.model_diverges = R.non_finite_predictions > 0 || R.diverged_windows > 0;
}

/// 2. Where the model fails: the GP's sensitivity to every input and its rows normalised to shares
/// (relevance), the residual in bins of every input, its cross-correlation with the controls, its RMS
/// per episode, and the GP's weighted held-out explained share. The model is consistent when it
/// does not diverge and no state's residual is structured.
void where(const DiagnosisOptions& o, const MeasurementSet& set, DiagnosisReport& R) {
  const Transitions& data = R.data;
  R.sensitivity = gp_sensitivity(R.gp, data, data.rows(false));
  R.relevance = shares(R.sensitivity);
  R.bins = bin_residuals(data, R.residual, R.input_names, o.bins);
  R.xcorr = cross_correlation(data, R.residual, o.max_lag);
  R.episode_rms = episode_rms(data, R.residual, static_cast<int>(set.episodes.size()));
  R.consistent = !R.model_diverges;
  for (const StateScore& s : R.states) R.consistent = R.consistent && !s.structured;
  R.gp_explained_total = weighted_heldout_explained(data, R.residual, R.gp.mean, R.weights);
}

/// The candidates searched only on request (LibraryEffect::on_request) that nothing asked for: neither
/// `--include` nor `--add` names them, `--exclude` does not already leave them out, and `model` does
/// not already hold them (a model file written by a run that included them).
std::vector<std::string> not_requested(const DiagnosisOptions& o, const ModelSpec& model,
                                       const std::vector<LibraryEffect>& candidates) {
  const auto named = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  const std::vector<RefitEffect> held = model_effects(model, candidates);
  std::vector<std::string> out;
  for (const LibraryEffect& effect : candidates)
    if (effect.on_request && !named(o.include, effect.name) && !named(o.exclude, effect.name) &&
        std::none_of(o.add.begin(), o.add.end(), [&](const EffectRequest& a) { return a.effect == effect.name; }) &&
        std::none_of(held.begin(), held.end(), [&](const RefitEffect& r) { return r.effect->name == effect.name; }))
      out.push_back(effect.name);
  return out;
}

/// 3. Which effect is missing: every effect of the library ranked under the criterion (unless the
/// model diverges), the verdict (decide), and with --auto the forward selection of several, judged
/// as a set (judge_selection).
void which(const DiagnosisOptions& o, const std::vector<LibraryEffect>& candidates, DiagnosisReport& R) {
  FitContext context = options_context(o, {&R.data, R.model, o.integrator, R.dt, o.substeps, R.weights, R.residual},
                                       &R.window_restarts);
  R.criterion = context.criterion;
  context.excluded = o.exclude;
  R.excluded = o.exclude;
  R.on_request = not_requested(o, R.model, candidates);
  context.excluded.insert(context.excluded.end(), R.on_request.begin(), R.on_request.end());
  // Candidates the criterion cannot identify on any data (under inverse dynamics the actuators' gains).
  for (const std::string& name : R.criterion->unidentifiable(candidates))
    if (std::find(context.excluded.begin(), context.excluded.end(), name) == context.excluded.end()) {
      context.excluded.push_back(name);
      R.criterion_excluded.push_back(name);
    }
  R.criterion_weights = context.weights;
  if (R.criterion->inverse_dynamics()) {
    for (const Quantity& q : force_components(*R.model.build()).forces) {
      R.channel_names.push_back(q.name);
      R.channel_units.push_back(q.unit);
    }
  } else {
    R.channel_names = R.state_names;
    for (const Quantity& q : system_signature(R.system).states) R.channel_units.push_back(q.unit);
  }
  const std::vector<RefitEffect> present = o.auto_select ? model_effects(R.model, candidates) : std::vector<RefitEffect>{};
  if (o.rank && !R.model_diverges) R.ranking = rank_effects(context, o.alias_gain, o.progress, present, o.gp.threads);
  // The GP sees (x_t, u_t) only: the residual of an effect of the input history (input_delay) looks
  // like noise to it. An effect that removes a large and significant share of the held-out residual
  // shows that the residual is not at its floor, whatever the GP found.
  const std::vector<std::string> in_model = names_of_effects(present);
  if (R.consistent && !R.ranking.empty() &&
      test_effect(R.ranking.front().fit, {o.min_explained, o.min_z}, in_model).accepted)
    R.consistent = false;
  R.verdict = decide(R, o, in_model);
  if (!o.auto_select || R.model_diverges) return;
  SelectionOptions so;
  so.method = o.search;
  so.max_subset = o.max_subset;
  so.alias_gain = o.alias_gain;
  so.min_explained = o.min_step_explained;
  so.min_z = o.min_z;
  so.threads = o.gp.threads;
  so.progress = o.progress;
  // Step 1 is the verdict: its ranking is the first step's, and without an explained verdict nothing is added.
  if (R.verdict.effect) {
    R.selection = select_effects(context, so, R.ranking);
    judge_selection(R.verdict, *R.selection, R.model, *R.criterion, o);
  } else {
    R.selection = Selection{};
    R.selection->method = o.search;
    R.selection->model = R.model;
    R.selection->rejected = R.ranking;
    R.selection->stop_reason = "no effect is added: " + R.verdict.reason;
  }
}

/// 4. Add the effect: the model the next diagnosis starts from (the --add effects, the --auto
/// selection or the verdict's effect, in that order of precedence) and, when there is one, the four
/// models on the held-out episodes: sim, sim + effect, sim + GP and sim + effect + GP, with the GP's
/// learned signal variance. Returns whether the four-model comparison exists.
bool add(const DiagnosisOptions& o, const ModelAsGiven& given, const std::vector<LibraryEffect>& candidates,
         const FitContext& settings, DiagnosisReport& R, ResidualGp& gp_after) {
  const Transitions& data = R.data;
  R.model_next = R.model;
  const ModelSpec* with_effect = nullptr;
  const ResidualGp* base_gp = nullptr;
  Matrix base_residual;
  ModelSpec proposed;
  if (!o.add.empty()) {
    with_effect = &R.model;
    base_gp = &given.gp;
    base_residual = given.residual;
    R.residual_after = R.residual;
    for (const EffectFit& f : R.added) R.comparison_effect += (R.comparison_effect.empty() ? "" : " + ") + f.effect;
  } else if (R.selection && !R.selection->steps.empty()) {
    R.model_next = R.selection->model;
    with_effect = &R.model_next;
    base_gp = &R.gp;
    base_residual = R.residual;
    R.residual_after = residual_of_model(R.model_next, settings);
    // The effects of the final set, each once (a step's lead can be an effect an earlier step had).
    for (const std::string& name : R.verdict.effects)
      R.comparison_effect += (R.comparison_effect.empty() ? "" : " + ") + name;
  } else if (R.verdict.effect) {
    proposed = R.model.with(named(candidates, R.verdict.effect->effect), R.verdict.effect->estimate);
    R.model_next = proposed;
    with_effect = &proposed;
    base_gp = &R.gp;
    base_residual = R.residual;
    R.residual_after = residual_of_model(proposed, settings);
    R.comparison_effect = R.verdict.effect->effect;
  }
  if (with_effect == nullptr) return false;
  gp_after = !o.add.empty() ? R.gp
                            : fit_residual_gp(make_step_model(*with_effect, o.integrator, R.dt, o.substeps), data,
                                              R.residual_after, o.gp);
  R.residual_base = base_residual;
  R.relevance_base = !o.add.empty() ? shares(gp_sensitivity(given.gp, data, data.rows(false))) : R.relevance;
  R.comparison.push_back({"sim", heldout_rmse(data, base_residual), Vector()});
  R.comparison.push_back({"sim+effect", heldout_rmse(data, R.residual_after), Vector()});
  R.comparison.push_back({"sim+GP", heldout_rmse(data, base_residual - base_gp->mean), base_gp->signal_variance});
  R.comparison.push_back({"sim+effect+GP", heldout_rmse(data, R.residual_after - gp_after.mean), gp_after.signal_variance});
  return true;
}

/// What a flexible model removes of what `model` leaves on the held-out rows under the report's
/// criterion (Criterion::flexible_share); `gp` the GP of `model`'s one-step residual when the
/// criterion needs it.
double flexible_share(const ModelSpec& model, const OneStepGp* gp, const DiagnosisOptions& o, const DiagnosisReport& R) {
  FitContext c{&R.data, model, o.integrator, R.dt, o.substeps, R.criterion_weights, Matrix()};
  c.criterion = R.criterion;
  return R.criterion->flexible_share(model, gp, c, o.gp);
}

/// The remainder test of the verdict (judge_remainder) on the model it proposes: model_next with the
/// GP of the four-model comparison, or, when --add effects were given and the verdict proposes one
/// more, the diagnosed model with it and a GP of its residual.
void judge_proposal(const DiagnosisOptions& o, const std::vector<LibraryEffect>& candidates, const FitContext& settings,
                    bool compared, const ResidualGp& gp_after, DiagnosisReport& R) {
  if (!R.verdict.effect || R.verdict.status != "explained") return;
  const Criterion& criterion = *R.criterion;
  if (o.add.empty() && compared && criterion.needs_one_step_gp()) {
    const OneStepGp gp{R.residual_after, gp_after};
    judge_remainder(R.verdict, flexible_share(R.model_next, &gp, o, R), o);
    return;
  }
  const ModelSpec proposed = o.add.empty() && compared
                                ? R.model_next
                                : R.model.with(named(candidates, R.verdict.effect->effect), R.verdict.effect->estimate);
  if (!criterion.needs_one_step_gp()) {
    judge_remainder(R.verdict, flexible_share(proposed, nullptr, o, R), o);
    return;
  }
  const Matrix residual = residual_of_model(proposed, settings);
  const ResidualGp gp = fit_residual_gp(make_step_model(proposed, o.integrator, R.dt, o.substeps), R.data, residual, o.gp);
  const OneStepGp one_step{residual, gp};
  judge_remainder(R.verdict, flexible_share(proposed, &one_step, o, R), o);
}

/// The measured inputs as `model` applies them (its input delay).
ControlSource applied_controls(const ModelSpec& model) {
  return [delay = model.input_delay](const MatrixCRef& u) { return delay_controls(Matrix(u), delay); };
}

/// 5. The error falls: the tests of system identification on the held-out episodes, the whiteness
/// of the diagnosed model's one-step residual and the free run (k = infinity) of sim, sim + effect
/// (when the four-model comparison exists) and sim + GP.
void falls(const DiagnosisOptions& o, const MeasurementSet& set, const ModelAsGiven& given, bool compared,
           DiagnosisReport& R) {
  R.whiteness = whiteness_test(R.data, R.residual, R.state_names, o.max_lag);
  std::vector<FreeRunModel> runs{{"sim", given.step, applied_controls(given.model)}};
  if (compared)
    runs.push_back({"sim+effect", make_step_model(R.model_next, o.integrator, R.dt, o.substeps), applied_controls(R.model_next)});
  runs.push_back({"sim+GP", given.gp.model, applied_controls(given.model)});
  R.free_run = free_run(set, R.heldout_episode_index, runs);
}

}  // namespace

DiagnosisReport diagnose(const MeasurementSet& input, const DiagnosisOptions& options) {
  options.validate();
  if (input.episodes.empty()) throw DataProblem("the data has no episodes");
  check_measurement_range(input);
  // A model file's data carry the model's name (<mujoco model="...">), not the file's path.
  if (const std::string model_name = system_signature(options.model.system).name; input.system.name != model_name)
    throw DataProblem("the data are of system '" + input.system.name + "'; the model is '" + model_name + "'");
  // The data's sampling step must be one the model can take (a MuJoCo model steps in whole multiples of
  // its timestep); every step model below is built at it.
  const DynamicsPtr model = options.model.build();
  if (const OwnIntegrator* own = own_integrator(*model))
    if (const std::optional<std::string> problem = own->step_problem(input.episodes.front().dt()))
      throw DataProblem("the data's sampling step: " + *problem);
  // --criterion auto: the data choose the criterion and its window, before the record is cut into
  // blocks (whose gaps depend on the window). Data too short for the rule's estimates keep the
  // one-step criterion, and the reason says so.
  DiagnosisOptions o = options;
  std::string criterion_reason;
  // Progress from the first moment: on a long record every stage below takes a while.
  if (o.progress)
    o.progress(fmt::format("{} samples in {} episode(s){}", input.sample_count(), input.episodes.size(),
                           o.choose_criterion ? "; choosing the criterion by the data" : ""));
  if (o.choose_criterion) {
    o.choose_criterion = false;
    try {
      const CriterionChoice choice = choose_criterion(input, o.model);
      o.criterion = choice.criterion;
      o.window = choice.window;
      o.instruments = choice.instruments;
      criterion_reason = choice.reason;
    } catch (const DataProblem& e) {
      o.criterion = FitCriterion::OneStep;
      o.window = 1;
      criterion_reason = std::string("one-step: the data are too short to choose by the rule (") + e.what() + ")";
    }
  }
  // A window the user gave that the episodes cannot hold would leave nothing to score.
  if (o.criterion == FitCriterion::Simulation && criterion_reason.empty() && o.window > simulation_window_cap(input))
    throw DataProblem(fmt::format(
        "--window {}: longer than the data allow, at most {} samples ({}); expected a shorter window", o.window,
        simulation_window_cap(input),
        input.episodes.size() == 1 ? fmt::format("a quarter of each of the {} blocks of the record, less 2",
                                                 kHeldoutBlockCount)
                                   : "half the shortest episode"));
  DiagnosisReport R;
  R.system = o.model.system;
  R.criterion_reason = criterion_reason;
  MeasurementSet blocks_as_episodes;
  const MeasurementSet& set = episodes_of(input, o, blocks_as_episodes, R);

  // One-step predictions of a model (its input delay applied to the measured inputs).
  const FitContext settings{&R.data, o.model, o.integrator, R.dt, o.substeps, Vector(), Matrix()};
  if (o.progress && !criterion_reason.empty()) o.progress("criterion: " + criterion_reason);
  if (o.progress)
    o.progress(fmt::format("the model's one-step residual on {} transitions, and its GP", R.data.size()));
  const ModelAsGiven given = model_as_given(o, settings);
  R.model_before = given.model;
  // The library and the model's declared effects; the fits below point into it.
  const std::vector<LibraryEffect> candidates = candidate_effects(given.model);
  add_requested_effects(o, given, candidates, settings, R);
  const auto step = make_step_model(R.model, o.integrator, R.dt, o.substeps);
  const Vector floors = fit_diagnosed_residual(o, given, settings, step, R);

  compare(o, set, *step, floors, R);
  where(o, set, R);
  which(o, candidates, R);
  ResidualGp gp_after;
  const bool compared = add(o, given, candidates, settings, R, gp_after);
  judge_proposal(o, candidates, settings, compared, gp_after, R);
  falls(o, set, given, compared, R);
  return R;
}

}  // namespace gpilqg::diagnosis
