#pragma once
/// @file diagnosis.hpp
/// Model diagnosis (`gpilqg diagnose`): compare a model with measurements, see where it fails, learn
/// which physical effect is missing, add it and watch the error fall.
///
/// The steps, each in its own file:
///  1. compare (transitions.hpp, residual_analysis.hpp): one-step and k-step predictions (RK4 by
///     default), RMSE, fit percent and the noise floor per state;
///  2. where (residual_analysis.hpp): residual per episode and in bins of every input, its
///     cross-correlation with the controls, and the GP's relevance of every input;
///  3. which (effect_fit.hpp): every effect of the library fitted on the training episodes and scored
///     on the held-out episodes, grouped into aliases, and a verdict; on the one-step error, or on the
///     simulation error over windows (criterion, simulation_error.hpp);
///  4. add: before and after on the held-out episodes for sim, sim + effect, sim + GP and
///     sim + effect + GP, with the GP's learned signal variance;
///  5. the tests of system identification on the held-out episodes: the whiteness of the diagnosed
///     model's one-step residual (whiteness.hpp) and the free-run simulation fit, k = infinity, of sim,
///     sim + effect and sim + GP (free_run.hpp).
///
/// Verdict.
/// Noise floor of state i: min(held-out RMSE of the model, held-out RMSE of the model corrected by a
/// GP fitted on the training episodes), the error nothing learnable from (x, u) removes.
///
///  - "consistent" when no state's residual is structured. State i is structured when the GP removes
///    more than `structure_threshold` of its held-out squared residual, i.e. its held-out RMSE exceeds
///    the noise floor by more than `floor_tolerance`, and no effect removes a large and significant
///    share of the held-out residual (explained >= min_explained, z >= min_z: the GP sees (x_t, u_t)
///    only, so the error of an input delay looks like noise to it). Nothing is proposed then.
///  - otherwise, when the best alias group is a finding (effect_test.hpp: identifiable, its 95%
///    interval excludes its value without it, it removes at least min_explained of the held-out
///    residual with z >= min_z) and, under the one-step criterion, removes at least relative_to_gp
///    (half) of what the GP removes on the same rows (with --auto the chosen set must, else it is
///    "partly_explained"; several effects may remove together what none does alone): "explained" or
///    "partly_explained" by the
///    remainder test, the same for every criterion: the model with the effect(s) plus a GP of its
///    residual (a flexible model) is scored under the criterion on the held-out rows; "explained"
///    when the effects leave at most explained_left_ratio (1.5) times what it leaves. A wrong effect
///    can soak up much of the residual; what it leaves keeps a structure the GP finds. With --auto
///    the same rules judge the chosen set.
///  - "unexplained" otherwise: the residual has structure no effect of the library accounts for.
///
/// Before all of these: "model_diverges" when the model's prediction diverges (not finite, or a state
/// beyond kDivergedStateMagnitude = 1e12, control/rollout.hpp) on any one-step transition or any k-step
/// window started from a measured state. The measurements stayed within the bound (check_measurement_range),
/// so such a model is not consistent with them whatever its other scores; the effects are not ranked
/// (a fit against a diverging model means nothing) and the reason counts the diverged predictions.

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/effect_selection.hpp"
#include "gpilqg/experiments/diagnosis/free_run.hpp"
#include "gpilqg/experiments/diagnosis/heldout_blocks.hpp"
#include "gpilqg/experiments/diagnosis/initial_state.hpp"
#include "gpilqg/experiments/diagnosis/instrumental_variables.hpp"
#include "gpilqg/experiments/diagnosis/residual_analysis.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"
#include "gpilqg/experiments/diagnosis/transitions.hpp"
#include "gpilqg/experiments/diagnosis/whiteness.hpp"

namespace gpilqg::diagnosis {

/// An effect to add: its library name and, optionally, its values (fitted when absent).
struct EffectRequest {
  std::string effect;
  std::optional<Vector> values;
};

struct DiagnosisOptions {
  ModelSpec model;                        ///< the model as given (preset or model file)
  std::vector<EffectRequest> add;         ///< --add, applied in order
  Integrator integrator = Integrator::RK4;
  int substeps = 1;
  double heldout_fraction = 0.3;          ///< share of the episodes held out
  std::vector<int> horizons = {1, 10, 50};
  GpSettings gp;
  int bins = 5;                           ///< quantile bins per input
  int max_lag = 20;                       ///< cross-correlation and residual autocorrelation lags
  /// Two effects are aliases when their joint fit removes less than this share of the held-out
  /// residual either leaves alone (rank_effects).
  double alias_gain = 0.05;
  double structure_threshold = 0.1;       ///< GP held-out explained fraction above which a state is structured
  double floor_tolerance = 1.05;          ///< held-out RMSE / noise floor above which a state is structured
  double min_explained = 0.1;             ///< "explained" needs at least this held-out fraction ...
  double min_z = 3.0;                     ///< ... this significance ...
  double relative_to_gp = 0.5;            ///< ... and this share of what the GP explains (one-step criterion)
  /// The error effects are fitted to and scored on (simulation_error.hpp): one-step, or simulation
  /// over windows of `window` samples from measured states (--criterion, --window).
  FitCriterion criterion = FitCriterion::OneStep;
  int window = 1;                         ///< samples per window; 1 unless the criterion is simulation
  /// Inverse dynamics in its instrumental-variable form (IDIM-IV, instrumental_variables.hpp;
  /// `--criterion inverse-dynamics-iv`): instruments from the model simulated over short windows.
  bool instruments = false;
  /// `--criterion auto`: criterion and window are chosen from the data by choose_criterion
  /// (criterion_choice.hpp) before anything else; `criterion` and `window` are then ignored.
  bool choose_criterion = false;
  bool rank = true;                       ///< false: skip the ranking (faster; verdict from the GP only)
  /// Candidates never ranked, searched or proposed (`--exclude`, resolved to names: excluded_effects).
  std::vector<std::string> exclude;
  /// Candidates searched only on request (LibraryEffect::on_request) that are ranked and searched too
  /// (`--include`, resolved to names: included_effects). The others are left out like `exclude`
  /// unless `add` names them, and reported apart from it (DiagnosisReport::on_request).
  std::vector<std::string> include;
  /// --auto: add several effects by forward selection with joint refits (effect_selection.hpp); the
  /// final model becomes model_next.
  bool auto_select = false;
  SearchMethod search = SearchMethod::Subsets;  ///< --auto: best subsets (subset_search.hpp) or forward
  int max_subset = 4;                          ///< --auto with subsets: the largest set searched
  /// "explained" needs the effects to leave at most this multiple of what the GP leaves on the
  /// held-out rows (weighted squared residual); a significant effect that leaves more is "partly
  /// explained" (see decide in diagnosis.cpp).
  double explained_left_ratio = 1.5;
  /// --auto: a step after the first adds its effect when it removes at least this share of the held-out
  /// residual left (and z >= min_z). Lower than min_explained: once the large effects are in, a real one
  /// can be a small share of a remainder that noise dominates; z is the test, this only keeps
  /// negligible effects out.
  double min_step_explained = 0.05;
  /// Optional: one line after the residual GP and after every fitted effect; it may throw to stop.
  std::function<void(const std::string&)> progress;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// Fit scores of one state.
struct StateScore {
  std::string name;
  double rmse = 0.0;           ///< one-step, all rows
  double fit_percent = 0.0;    ///< one-step, on the increments x_{t+1} - x_t
  double noise_floor = 0.0;    ///< min(held-out RMSE of the model, of the model + GP) (diagnosis.cpp)
  double gp_noise_std = 0.0;   ///< the GP's fitted noise std sn_i (for reference)
  double heldout_rmse = 0.0;   ///< one-step, held-out rows
  double gp_explained = 0.0;   ///< held-out structure the GP finds
  bool structured = false;
};

struct KStepScore {
  int k = 1;
  int stride = 1;
  int windows = 0;
  int diverged = 0;
  Vector rmse;         ///< n
  Vector fit_percent;  ///< n, on the states x_{s+k}
  KStepPredictions predictions;
};

/// One of the four models of the "add" step.
struct ModelScore {
  std::string name;          ///< "sim", "sim+effect", "sim+GP", "sim+effect+GP"
  Vector heldout_rmse;       ///< n
  Vector signal_variance;    ///< n, the GP's sf^2 (empty for the models without GP)
};

struct Verdict {
  /// "explained", "partly_explained", "unexplained", "consistent", "model_diverges"
  std::string status;
  /// The proposed effect ("explained" and "partly_explained"). With --auto and a chosen set, the
  /// set's last joint fit: its lead here, the other members in effect->refitted.
  std::optional<EffectFit> effect;
  std::vector<std::string> aliases;
  /// Rival explanations of a single proposed effect: ranked effects that are not its aliases but
  /// that the held-out rows do not tell from it (RankedEffect::rival). The data support the
  /// proposed effect no better than any of these; more data, or data that excite them differently,
  /// decide.
  std::vector<std::string> rivals;
  /// --auto: every effect of the chosen model beyond M_0's (empty without --auto).
  std::vector<std::string> effects;
  /// Shares of the diagnosed model's weighted held-out squared residual left by the proposed
  /// effect(s) and by the GP (1 when nothing is proposed).
  double left = 1.0, gp_left = 1.0;
  /// The remainder test (diagnosis.cpp, judge_remainder): the share of what the proposed effect(s)
  /// leave on the held-out rows, under the criterion, that a flexible model removes (the model with
  /// them plus a GP of its residual); 0 when no effect is proposed.
  double remainder = 0.0;
  std::string reason;                    ///< one sentence: why this verdict
};

struct DiagnosisReport {
  std::string system;
  ModelSpec model_before;                ///< as given
  ModelSpec model;                       ///< as diagnosed: model_before plus the added effects
  /// Fits of the --add effects (values given: estimate = value). The fitted ones are fitted jointly,
  /// with the model's own effects (`refitted`), so they share the scores of the joint fit.
  std::vector<EffectFit> added;
  std::vector<EffectValues> refitted;    ///< the model's own effects, refitted jointly with the --add effects
  std::optional<Selection> selection;    ///< --auto: the selection path
  ModelSpec model_next;                  ///< what the next diagnosis should start from
  std::vector<std::string> state_names, control_names, input_names;
  double dt = 0.0;
  long samples = 0;                      ///< transitions (of the blocks' kept samples for a single record)
  /// A single-episode record: its blocks (heldout_blocks.hpp). Every "episode" below, its ids and
  /// indices, is then a block: block b is episode b, id b.
  std::optional<HeldoutBlocks> blocks;
  std::vector<long> heldout_episode_ids;
  std::vector<int> heldout_episode_index;
  Transitions data;
  Matrix predicted;                      ///< N x n, one-step
  Matrix residual;                       ///< N x n
  int non_finite_predictions = 0;        ///< one-step predictions that diverged (prediction_diverged)
  /// True when the model diverges on the data: a one-step prediction or a k-step window diverged
  /// (verdict "model_diverges", consistent false, no ranking).
  bool model_diverges = false;
  int diverged_windows = 0;              ///< k-step windows that diverged, over all horizons
  int windows = 0;                       ///< k-step windows, over all horizons (diverged included)
  std::vector<StateScore> states;
  std::vector<KStepScore> k_step;
  ResidualGp gp;
  Matrix sensitivity;                    ///< n x (n + m), raw
  Matrix relevance;                      ///< n x (n + m), rows normalised to sum 1
  std::vector<BinnedResidual> bins;
  CrossCorrelation xcorr;
  Matrix episode_rms;                    ///< episodes x n
  bool consistent = false;
  double gp_explained_total = 0.0;       ///< weighted, held-out
  Vector weights;                        ///< n, 1 / noise floor^2
  /// The criterion of the fits below (ranking, verdict, added, selection, the remainder test), made
  /// for these data and the diagnosed model (criteria/criterion.hpp): its name, window, accelerations
  /// (inverse dynamics), windows' starts (simulation) and instruments (IDIM-IV).
  std::shared_ptr<const Criterion> criterion = one_step_criterion();
  /// `--criterion auto`: the sentence saying which criterion the data chose and why (empty when the
  /// user chose it).
  std::string criterion_reason;
  /// The channels of the criterion, in which the fits' held-out RMSE are given: the states (one-step,
  /// simulation) or the generalised-force components (inverse dynamics, e.g. Q_shoulder [N m]), with
  /// the weights 1 / sigma_i^2 the fits use in them.
  std::vector<std::string> channel_names, channel_units;
  Vector criterion_weights;
  /// Simulation criterion: simulated states of the diagnosed model that diverged, each followed by a
  /// restart from the measurement (0 for the one-step criterion, whose divergences are counted in
  /// non_finite_predictions).
  int window_restarts = 0;
  std::vector<RankedEffect> ranking;
  std::vector<std::string> excluded;     ///< candidates left out by the user (DiagnosisOptions::exclude)
  std::vector<std::string> on_request;   ///< candidates searched only on request, not requested (DiagnosisOptions::include)
  /// Candidates the criterion cannot identify and leaves out: under inverse dynamics the actuators'
  /// gains and gears (the force residual is homogeneous in them and the inertias).
  std::vector<std::string> criterion_excluded;
  Verdict verdict;
  /// The "add" step (present when effects were added, or when a proposal exists): the four models.
  std::vector<ModelScore> comparison;
  std::string comparison_effect;         ///< what "effect" means in the four rows
  Matrix residual_base;                  ///< N x n, one-step residual of "sim" in the comparison
  Matrix residual_after;                 ///< N x n, one-step residual of sim + effect (when comparison exists)
  Matrix relevance_base;                 ///< n x (n + m), relevance of the "sim" model's GP
  /// Whiteness of the held-out one-step residual of the diagnosed model (`residual`).
  Whiteness whiteness;
  /// Free run of every held-out episode: "sim" (model_before), "sim+effect" (model_next, present when
  /// the four-model comparison is) and "sim+GP" (model_before plus the mean of its residual GP).
  std::vector<FreeRunEpisode> free_run;
};

/// Runs the diagnosis. Data of several episodes hold whole episodes out (heldout_episodes); a single
/// episode is cut into blocks with gaps (heldout_blocks.hpp: split_heldout_blocks with the gap
/// heldout_block_gap(horizons)) and each block is an episode from then on. Throws std::invalid_argument
/// for bad options or data that do not fit the model (no episode, a single record too short for its
/// blocks, dt varying between episodes, a value beyond 1e12: check_measurement_range).
DiagnosisReport diagnose(const MeasurementSet& data, const DiagnosisOptions& options);

}  // namespace gpilqg::diagnosis
