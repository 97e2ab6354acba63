#pragma once
/// @file effect_selection.hpp
/// Several missing effects in one call (`gpilqg diagnose --auto`). Two searches share these types:
/// the best-subset search (subset_search.hpp, the default), which finds sets whose members are weak
/// alone, and the forward selection below, kept for comparison (`--search forward`).
///
/// Forward selection with joint refits.
///
/// Start from the diagnosed model M_0 with its one-step residual r_0 and the noise-floor weights
/// w_i = 1 / floor_i^2 (diagnosis.hpp). The effects M_0 already has (model_effects) are refitted
/// with every new one. Step k = 1, 2, ...:
///  1. every candidate of the library (not chosen, not declared the same physics as a chosen effect)
///     is fitted jointly with the chosen effects on the training episodes (fit_jointly: the chosen
///     effects start from their values in M_{k-1} and are refitted together with the candidate);
///  2. each joint fit is scored on the held-out episodes against M_{k-1}: the fraction of M_{k-1}'s
///     weighted held-out squared residual it removes, "explained", and its z score from batch means of
///     the per-sample reduction (effect_fit.hpp, step 4);
///  3. the candidate with the largest held-out reduction is added when it is significant and not
///     negligible, z >= min_z (3, the verdict's) and explained >= min_explained (5%: once the large
///     effects are in, a real one can be a small share of a remainder that noise dominates). Step 1 is
///     the verdict (10%, and half of what the GP explains);
///     M_k is then M_0 with the chosen effects at their joint estimates. Otherwise selection stops;
///  4. a backward check: an effect chosen at an earlier step whose joint 95% interval now contains its
///     value in M_0 (a force of 0, a gain of 1, the preset's parameter, no delay) is dropped and the
///     others refitted jointly: a later effect explains what it had soaked up (a gain fitted first
///     to what a constant force does, say). Effects M_0 had are never dropped.
/// Reaching the noise floor is not a stopping rule: the floor comes from a GP of (x_t, u_t), which
/// cannot see an effect of the input history (input_delay), so a model can be at that floor with an
/// effect still missing; only the held-out test decides.
///
/// Why a held-out test and not an information criterion. AIC and BIC with the noise floor as the known
/// variance assume independent residuals; one-step residuals of one episode are serially correlated
/// (a missing effect makes them so), and the effective sample size is unknown, so the penalty is
/// uncalibrated and a spurious effect gets in on long records. Held-out whole episodes penalise
/// complexity directly: an effect that fits the training noise does not lower the held-out error. The
/// batch-means z score accounts for the serial correlation that remains, and explained >= 5% keeps
/// effects whose contribution is real but negligible out of the model.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"

namespace gpilqg::diagnosis {

/// The effect of `candidates` (candidate_effects of a model) called `name`; std::invalid_argument
/// when there is none.
const LibraryEffect& named(const std::vector<LibraryEffect>& candidates, std::string_view name);

/// The effects `model` has beyond its preset, at their current values: its forces (library and
/// user-declared), the actuator gain when it is not 1, its recalibrated parameters, its input delay.
/// These are refitted with a new effect. The pointers point into `candidates`, which must hold
/// candidate_effects(model) (or a superset) and outlive the result.
std::vector<RefitEffect> model_effects(const ModelSpec& model, const std::vector<LibraryEffect>& candidates);

/// How --auto searches: every subset of up to max_subset effects (subset_search.hpp), or forward.
enum class SearchMethod { Subsets, Forward };

/// "subsets" or "forward".
const char* to_string(SearchMethod method);

struct SelectionOptions {
  SearchMethod method = SearchMethod::Subsets;
  int max_subset = 4;           ///< subsets: the largest size searched exhaustively (subset_search.hpp)
  double alias_gain = 0.05;     ///< rank_effects' alias rule
  double min_explained = 0.05;  ///< step 3: explained >= this ...
  double min_z = 3.0;           ///< ... and z >= this
  int max_steps = 32;           ///< at most this many effects (a 7-joint arm's friction alone takes 14)
  int threads = 1;              ///< candidates fitted at once (and the subset search's exact fits of one size)
  std::function<void(const std::string&)> progress;
};

/// One step of the path: the effect added, with the values of the effects refitted jointly with it.
struct SelectionStep {
  EffectFit fit;               ///< fit.refitted: the earlier effects' new values; explained, z: against M_{k-1}
  ModelSpec model;             ///< M_k
  std::vector<RankedEffect> ranking;  ///< every candidate of this step, best first
  std::vector<std::string> removed;   ///< earlier effects dropped by the backward check (step 4)
};

struct Selection {
  SearchMethod method = SearchMethod::Subsets;
  std::vector<SelectionStep> steps;       ///< the effects added, in order (subsets: one step per accepted size)
  ModelSpec model;                        ///< the final model (M_0 when nothing was added)
  std::vector<RankedEffect> rejected;     ///< the candidates of the step that stopped the selection
  std::string stop_reason;                ///< one sentence
};

/// The names of `effects`.
std::vector<std::string> names_of_effects(const std::vector<RefitEffect>& effects);

/// The share each step of `selection` was accepted on: judged_share against the effects of the step
/// before (those `model_as_given` has, at the first step), so on the channels the step's new members act
/// on. What the text report's section 3b prints and the JSON's `steps[].judged` holds.
std::vector<JudgedShare> judged_step_shares(const Selection& selection, const ModelSpec& model_as_given,
                                            const std::string& residual);

/// M_0 (`base`) with the effect of `fit` and those it refitted at their joint estimates.
ModelSpec model_after(const ModelSpec& base, const EffectFit& fit, const std::vector<LibraryEffect>& candidates);

/// The backward check: while a member of the joint fit (its lead or an effect of fit.refitted) that
/// M_0 (context.model) does not have has a joint 95% interval containing its value in M_0, it is
/// dropped (its name appended to `removed`) and the rest refitted jointly on `step_context`, led by
/// the first member M_0 does not have. A fit of a single member is returned as it is.
EffectFit without_redundant(EffectFit fit, const FitContext& context, const FitContext& step_context,
                            const std::vector<LibraryEffect>& candidates, std::vector<std::string>& removed);

/// Runs the selection of options.method from context.model = M_0 (context.residual its residual, context.weights the
/// floor weights). `first` (optional) is step 1's ranking when the caller already has it: rank_effects
/// on the same context with refit = model_effects(M_0).
Selection select_effects(const FitContext& context, const SelectionOptions& options,
                         std::vector<RankedEffect> first = {});

}  // namespace gpilqg::diagnosis
