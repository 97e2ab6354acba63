#include "gpilqg/experiments/diagnosis/effect_selection.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/subset_search.hpp"

namespace gpilqg::diagnosis {

const LibraryEffect& named(const std::vector<LibraryEffect>& candidates, std::string_view name) {
  for (const LibraryEffect& effect : candidates)
    if (effect.name == name) return effect;
  throw std::invalid_argument("no candidate effect is called '" + std::string(name) + "'");
}

std::vector<RefitEffect> model_effects(const ModelSpec& model, const std::vector<LibraryEffect>& candidates) {
  std::vector<RefitEffect> out;
  for (const LibraryEffect& effect : candidates) {
    bool present = false;
    switch (effect.kind) {
      case EffectKind::Force:
        present = std::any_of(model.forces.begin(), model.forces.end(), [&](const auto& f) { return f.first == effect.name; });
        break;
      case EffectKind::ActuatorGain:
        present = model.actuator_gain != 1.0;
        break;
      case EffectKind::Recalibration:
        present = model.parameters.count(effect.recalibrated) > 0;
        break;
      case EffectKind::InputDelay:
        present = model.input_delay != 0.0;
        break;
    }
    if (present) out.push_back({&effect, model.current_values(effect)});
  }
  return out;
}

const char* to_string(SearchMethod method) { return method == SearchMethod::Subsets ? "subsets" : "forward"; }

ModelSpec model_after(const ModelSpec& base, const EffectFit& fit, const std::vector<LibraryEffect>& candidates) {
  ModelSpec model = base.with(named(candidates, fit.effect), fit.estimate);
  for (const EffectValues& v : fit.refitted) model = model.with(named(candidates, v.effect), v.estimate);
  return model;
}

std::vector<std::string> names_of_effects(const std::vector<RefitEffect>& effects) {
  std::vector<std::string> out;
  for (const RefitEffect& r : effects) out.push_back(r.effect->name);
  return out;
}

std::vector<JudgedShare> judged_step_shares(const Selection& selection, const ModelSpec& model_as_given,
                                            const std::string& residual) {
  std::vector<std::string> before = names_of_effects(model_effects(model_as_given, candidate_effects(model_as_given)));
  std::vector<JudgedShare> out;
  for (const SelectionStep& step : selection.steps) {
    out.push_back(judged_share(step.fit, before, residual));
    before = {step.fit.effect};
    for (const EffectValues& v : step.fit.refitted) before.push_back(v.effect);
  }
  return out;
}

/// The backward check after a step. A member of the joint fit (the lead or a refitted one) that M_0
/// does not have and whose joint 95% interval contains its value in M_0 (a force of 0, a gain of 1,
/// the preset's parameter, no delay) is no longer needed: another member explains what it had soaked
/// up. It is dropped and the others are refitted jointly, until none is left to drop. Effects M_0
/// had already are never dropped; a fit left with a single member keeps it (the test of the step
/// then rejects it).
EffectFit without_redundant(EffectFit fit, const FitContext& context, const FitContext& step_context,
                            const std::vector<LibraryEffect>& candidates, std::vector<std::string>& removed) {
  const std::vector<std::string> in_m0 = names_of_effects(model_effects(context.model, candidates));
  const auto given = [&](const std::string& name) { return std::find(in_m0.begin(), in_m0.end(), name) != in_m0.end(); };
  for (;;) {
    std::vector<EffectValues> members{own_values(fit)};
    members.insert(members.end(), fit.refitted.begin(), fit.refitted.end());
    if (members.size() < 2) return fit;
    const auto drop = std::find_if(members.begin(), members.end(),
                                   [&](const EffectValues& v) { return !given(v.effect) && interval_contains_null(v); });
    if (drop == members.end()) return fit;
    removed.push_back(drop->effect);
    members.erase(drop);
    // The new lead: the first member M_0 does not have, else the first.
    const auto lead = std::find_if(members.begin(), members.end(), [&](const EffectValues& v) { return !given(v.effect); });
    const EffectValues first = lead != members.end() ? *lead : members.front();
    std::vector<RefitEffect> keep;
    for (const EffectValues& v : members)
      if (v.effect != first.effect) keep.push_back({&named(candidates, v.effect), v.estimate});
    fit = fit_jointly(named(candidates, first.effect), keep, step_context, first.estimate);
  }
}

Selection select_effects(const FitContext& context, const SelectionOptions& o, std::vector<RankedEffect> first) {
  if (context.data == nullptr) throw std::invalid_argument("select_effects: no data");
  if (o.method == SearchMethod::Subsets) return select_subsets(context, o, std::move(first));
  Selection S;
  S.method = SearchMethod::Forward;
  S.model = context.model;
  const std::vector<LibraryEffect> candidates = candidate_effects(context.model);
  std::vector<RefitEffect> chosen = model_effects(context.model, candidates);
  FitContext step_context = context;  // model stays M_0; residual becomes M_{k-1}'s
  for (int k = 1;; ++k) {
    if (k > o.max_steps) {
      S.stop_reason = fmt::format("the selection stops at its limit of {} effects", o.max_steps);
      break;
    }
    std::vector<RankedEffect> ranking =
        k == 1 && !first.empty() ? std::move(first)
                                 : rank_effects(step_context, o.alias_gain, o.progress, chosen, o.threads);
    if (ranking.empty()) {
      S.stop_reason = "no candidate effect is left";
      break;
    }
    const EffectFit& best = ranking.front().fit;
    std::vector<std::string> removed;
    const EffectTestResult finding = test_effect(best, {o.min_explained, o.min_z}, names_of_effects(chosen));
    if (!finding.accepted) {
      S.stop_reason = fmt::format("the best remaining candidate '{}' is not added: {}", best.effect, finding.reason);
      S.rejected = std::move(ranking);
      break;
    }
    const EffectFit added = without_redundant(best, context, step_context, candidates, removed);
    SelectionStep step{added, model_after(context.model, added, candidates), std::move(ranking), removed};
    if (o.progress) o.progress(fmt::format("step {}: added {} ({:.1f}% of the held-out residual left)", k, added.effect,
                                           100.0 * added.explained));
    // The chosen effects and their new starts, in the order they were chosen.
    std::vector<RefitEffect> next;
    for (const RefitEffect& r : chosen)
      for (const EffectValues& v : added.refitted)
        if (v.effect == r.effect->name) next.push_back({r.effect, v.estimate});
    next.push_back({&named(candidates, added.effect), added.estimate});
    chosen = std::move(next);
    step_context.residual = criterion_residual(step.model, context);
    S.model = step.model;
    S.steps.push_back(std::move(step));
  }
  return S;
}

}  // namespace gpilqg::diagnosis
