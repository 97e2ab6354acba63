#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/experiments/diagnosis/criteria/inverse_dynamics.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"

namespace gpilqg::diagnosis {

int worst_state(const DiagnosisReport& r) {
  int worst = 0;
  double ratio = -1.0;
  for (std::size_t i = 0; i < r.states.size(); ++i) {
    const double q = r.states[i].heldout_rmse / std::max(r.states[i].noise_floor, 1e-300);
    if (q > ratio) {
      ratio = q;
      worst = static_cast<int>(i);
    }
  }
  return worst;
}

int worst_channel(const DiagnosisReport& r) {
  if (!r.criterion->inverse_dynamics()) return worst_state(r);
  if (r.ranking.empty() || r.criterion_weights.size() != r.ranking.front().fit.heldout_rmse_before.size()) return 0;
  Eigen::Index worst = 0;
  (r.ranking.front().fit.heldout_rmse_before.array() * r.criterion_weights.array().sqrt()).maxCoeff(&worst);
  return static_cast<int>(worst);
}

namespace {

using nlohmann::json;

json by_name(const std::vector<std::string>& names, const VectorCRef& values) {
  json out = json::object();
  for (std::size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < values.size(); ++i)
    out[names[i]] = values(static_cast<Eigen::Index>(i));
  return out;
}

json vector_json(const VectorCRef& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

json parameters_json(const EffectFit& f, const Vector& values) {
  json out = json::object();
  for (std::size_t i = 0; i < f.parameters.size(); ++i) out[f.parameters[i].name] = values(static_cast<Eigen::Index>(i));
  return out;
}

/// An interval bound: a number, or null where the interval is unbounded (a covariance that is not finite).
json bound_json(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

/// {"effect", "parameters", "parameter_ci95", "initial", "null_value", "interval_holds_null"} of an
/// effect refitted jointly with another.
json values_json(const EffectValues& v) {
  json parameters = json::object(), ci = json::object(), initial = json::object(), null = json::object();
  for (std::size_t i = 0; i < v.parameters.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    parameters[v.parameters[i].name] = v.estimate(k);
    ci[v.parameters[i].name] = {bound_json(v.ci_low(k)), bound_json(v.ci_high(k))};
    initial[v.parameters[i].name] = v.initial(k);
    if (v.null_value.size() == v.estimate.size()) null[v.parameters[i].name] = v.null_value(k);
  }
  return {{"effect", v.effect},
          {"parameters", parameters},
          {"parameter_ci95", ci},
          {"initial", initial},
          {"null_value", null},
          {"interval_holds_null", interval_contains_null(v)},
          {"smoothing_v0", v.smoothing > 0.0 ? json(v.smoothing) : json(nullptr)}};
}

json fit_json(const EffectFit& f, const DiagnosisReport& r, int state) {
  json acts_on = json::array();
  for (int channel : f.acts_on)
    if (channel >= 0 && channel < static_cast<int>(r.channel_names.size()))
      acts_on.push_back(r.channel_names[static_cast<std::size_t>(channel)]);
  json ci = json::object();
  for (std::size_t i = 0; i < f.parameters.size(); ++i)
    ci[f.parameters[i].name] = {bound_json(f.ci_low(static_cast<Eigen::Index>(i))),
                                bound_json(f.ci_high(static_cast<Eigen::Index>(i)))};
  json units = json::object();
  for (const auto& p : f.parameters) units[p.name] = p.unit;
  const json scale = f.scale.size() == f.estimate.size() ? parameters_json(f, f.scale) : json::object();
  return {{"effect", f.effect},
          {"parameters", parameters_json(f, f.estimate)},
          {"parameter_ci95", ci},
          {"units", units},
          {"initial", parameters_json(f, f.initial)},
          {"linear_estimate", parameters_json(f, f.linear_estimate)},
          {"smoothing_v0", f.smoothing > 0.0 ? json(f.smoothing) : json(nullptr)},
          {"explained", f.explained},
          {"explained_ci95", {f.explained - f.explained_ci, f.explained + f.explained_ci}},
          {"z_score", f.z_score},
          {"identifiable", f.identifiable},
          {"not_identifiable", f.identifiable ? json(nullptr) : json(f.not_identifiable)},
          {"null_value", f.null_value.size() == f.estimate.size() ? parameters_json(f, f.null_value) : json::object()},
          {"interval_holds_null", interval_contains_null(own_values(f))},
          {"scale", scale},
          {"acts_on", acts_on},
          {"evaluations", f.evaluations},
          {"heldout_state", r.channel_names[static_cast<std::size_t>(state)]},
          {"heldout_rmse_before", f.heldout_rmse_before(state)},
          {"heldout_rmse_after", f.heldout_rmse_after(state)},
          {"heldout_rmse_by_state",
           {{"before", by_name(r.channel_names, f.heldout_rmse_before)}, {"after", by_name(r.channel_names, f.heldout_rmse_after)}}}};
}

json where_json(const DiagnosisReport& r) {
  json bins = json::object();
  for (std::size_t i = 0; i < r.state_names.size(); ++i) {
    json per_input = json::object();
    for (const BinnedResidual& b : r.bins)
      per_input[b.input] = {{"edges", vector_json(b.edges)}, {"rmse", vector_json(b.rms.row(static_cast<Eigen::Index>(i)).transpose())}, {"count", b.count}};
    bins[r.state_names[i]] = per_input;
  }
  json xcorr = json::object();
  for (std::size_t i = 0; i < r.state_names.size(); ++i) {
    json per_control = json::object();
    for (std::size_t j = 0; j < r.control_names.size(); ++j) {
      const auto ii = static_cast<Eigen::Index>(i), jj = static_cast<Eigen::Index>(j);
      per_control[r.control_names[j]] = {{"max_abs", r.xcorr.max_abs(ii, jj)}, {"band95", r.xcorr.band(ii, jj)},
                                         {"significant", r.xcorr.max_abs(ii, jj) > r.xcorr.band(ii, jj)},
                                         {"values", vector_json(r.xcorr.values[i][j])}};
    }
    xcorr[r.state_names[i]] = per_control;
  }
  json episodes = json::object();
  for (std::size_t i = 0; i < r.state_names.size(); ++i)
    episodes[r.state_names[i]] = vector_json(r.episode_rms.col(static_cast<Eigen::Index>(i)));
  return {{"bins", bins}, {"cross_correlation", {{"lags", {-r.xcorr.max_lag, r.xcorr.max_lag}}, {"states", xcorr}}},
          {"episode_rmse", episodes}};
}

/// The instruments of the IV form of inverse dynamics (instrumental_variables.hpp), or null.
json instruments_json(const DiagnosisReport& r) {
  const InverseDynamicsCriterion* criterion = r.criterion->inverse_dynamics();
  const Instruments* instruments = criterion != nullptr ? criterion->instruments() : nullptr;
  if (instruments == nullptr) return nullptr;
  return {{"window", instruments->window},
          {"reach", instruments->reach},
          {"instrumented_rows", instruments->instrumented_rows()},
          {"rows", instruments->instrumented.size()},
          {"restarts", instruments->restarts}};
}

json channel_weights_json(const DiagnosisReport& r) {
  const InverseDynamicsCriterion* criterion = r.criterion->inverse_dynamics();
  if (criterion == nullptr || criterion->noise().size() != static_cast<Eigen::Index>(r.channel_names.size())) return nullptr;
  json out = json::array();
  for (std::size_t i = 0; i < r.channel_names.size(); ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    out.push_back({{"channel", r.channel_names[i]}, {"noise", criterion->noise()(c)}, {"left", criterion->left()(c)},
                   {"weight", r.criterion_weights(c)}, {"standstill_rows", criterion->standstill_counts().at(i)}});
  }
  return out;
}

json whiteness_json(const DiagnosisReport& r) {
  const Whiteness& w = r.whiteness;
  json states = json::array();
  for (const StateWhiteness& s : w.states)
    states.push_back({{"name", s.name}, {"autocorrelation", vector_json(s.autocorrelation)}, {"outside_band", s.outside_band},
                      {"ljung_box_q", s.ljung_box}, {"p_value", s.p_value}, {"white", s.white}});
  return {{"test", "ljung_box"},
          {"lags", w.max_lag},
          {"samples", w.samples},
          {"band", w.band},
          {"level", w.level},
          {"degrees_of_freedom", w.degrees_of_freedom},
          {"critical_value", w.critical_value},
          {"states", states}};
}

json free_run_json(const DiagnosisReport& r) {
  json out = json::array();
  for (const FreeRunEpisode& e : r.free_run) {
    json models = json::array();
    for (const FreeRunTrajectory& m : e.models)
      models.push_back({{"name", m.model}, {"fit_percent", by_name(r.state_names, m.fit_percent)}, {"diverged", m.diverged},
                        {"steps", m.steps}});
    out.push_back({{"episode", e.id}, {"index", e.index}, {"steps", e.t.size() - 1}, {"models", models}});
  }
  return out;
}

}  // namespace

nlohmann::json report_json(const DiagnosisReport& r) {
  const int state = worst_channel(r);
  json states = json::array();
  for (const StateScore& s : r.states)
    states.push_back({{"name", s.name}, {"rmse", s.rmse}, {"noise_floor", s.noise_floor}, {"fit_percent", s.fit_percent},
                      {"heldout_rmse", s.heldout_rmse}, {"gp_noise_std", s.gp_noise_std},
                      {"gp_explained", s.gp_explained}, {"structured", s.structured}});
  json relevance = json::object(), sensitivity = json::object();
  for (std::size_t i = 0; i < r.state_names.size(); ++i) {
    relevance[r.state_names[i]] = by_name(r.input_names, r.relevance.row(static_cast<Eigen::Index>(i)).transpose());
    sensitivity[r.state_names[i]] = by_name(r.input_names, r.sensitivity.row(static_cast<Eigen::Index>(i)).transpose());
  }
  json k_step = json::array();
  for (const KStepScore& k : r.k_step) {
    json per_state = json::array();
    for (std::size_t i = 0; i < r.state_names.size(); ++i)
      per_state.push_back({{"name", r.state_names[i]}, {"rmse", k.rmse(static_cast<Eigen::Index>(i))},
                           {"fit_percent", k.fit_percent(static_cast<Eigen::Index>(i))}});
    k_step.push_back({{"k", k.k}, {"stride", k.stride}, {"windows", k.windows}, {"diverged", k.diverged}, {"states", per_state}});
  }
  json ranking = json::array();
  for (const RankedEffect& g : r.ranking) {
    json entry = fit_json(g.fit, r, state);
    json aliases = json::array(), alias_fits = json::array();
    for (const EffectFit& a : g.aliases) {
      aliases.push_back(a.effect);
      alias_fits.push_back(fit_json(a, r, state));
    }
    entry["aliases"] = aliases;
    entry["alias_fits"] = alias_fits;
    entry["behind_first"] = g.behind_first;
    entry["behind_first_ci"] = g.behind_first_ci;
    entry["rival"] = g.rival;
    ranking.push_back(entry);
  }
  json verdict = {{"status", r.verdict.status}, {"reason", r.verdict.reason},   {"aliases", r.verdict.aliases},
                  {"rivals", r.verdict.rivals},  {"effects", r.verdict.effects}, {"left", r.verdict.left},       {"gp_left", r.verdict.gp_left},
                  {"remainder", r.verdict.remainder}};
  if (r.verdict.effect) {
    // The judged effect or set: the lead's values, every member's in "members" (one joint fit).
    verdict["effect"] = r.verdict.effect->effect;
    verdict["parameters"] = parameters_json(*r.verdict.effect, r.verdict.effect->estimate);
    verdict["explained"] = 1.0 - r.verdict.left;
    json members = json::array({values_json(own_values(*r.verdict.effect))});
    for (const EffectValues& v : r.verdict.effect->refitted) members.push_back(values_json(v));
    verdict["members"] = members;
  } else {
    verdict["effect"] = nullptr;
    verdict["parameters"] = json::object();
    verdict["explained"] = r.ranking.empty() ? 0.0 : r.ranking.front().fit.explained;
    verdict["members"] = json::array();
  }
  json comparison = json::object();
  if (!r.comparison.empty()) {
    json models = json::array();
    for (const ModelScore& m : r.comparison) {
      json entry = {{"name", m.name}, {"heldout_rmse", by_name(r.state_names, m.heldout_rmse)}};
      entry["gp_signal_variance"] = m.signal_variance.size() > 0 ? by_name(r.state_names, m.signal_variance) : json(nullptr);
      models.push_back(entry);
    }
    comparison = {{"effect", r.comparison_effect}, {"models", models}};
  }
  json added = json::array();
  for (const EffectFit& f : r.added) added.push_back(fit_json(f, r, state));
  json refitted = json::array();
  for (const EffectValues& v : r.refitted) refitted.push_back(values_json(v));
  json selection = nullptr;
  if (r.selection) {
    json steps = json::array();
    const std::vector<JudgedShare> judged_shares = judged_step_shares(*r.selection, r.model, "");
    for (std::size_t k = 0; k < r.selection->steps.size(); ++k) {
      const SelectionStep& step = r.selection->steps[k];
      json entry = fit_json(step.fit, r, state);
      json joint = json::array();
      for (const EffectValues& v : step.fit.refitted) joint.push_back(values_json(v));
      entry["refitted"] = joint;
      // The share the step was accepted on: on the channels its new members act on (effect_test.hpp).
      const JudgedShare& judged = judged_shares[k];
      json channels = json::array();
      for (std::size_t i = 0; i < r.channel_names.size(); ++i)
        if (judged.channels.empty() || std::binary_search(judged.channels.begin(), judged.channels.end(), static_cast<int>(i)))
          channels.push_back(r.channel_names[i]);
      entry["judged"] = {{"explained", judged.share.explained},
                         {"explained_ci95", {judged.share.explained - judged.share.explained_ci,
                                             judged.share.explained + judged.share.explained_ci}},
                         {"z_score", judged.share.z_score},
                         {"channels", channels}};
      entry["removed"] = step.removed;
      entry["heldout_rmse_after_by_state"] = by_name(r.channel_names, step.fit.heldout_rmse_after);
      entry["model"] = model_file_text(step.model);
      steps.push_back(entry);
    }
    selection = {{"method", to_string(r.selection->method)},
                 {"steps", steps},
                 {"stop_reason", r.selection->stop_reason},
                 {"model", model_file_text(r.selection->model)}};
  }
  json heldout_ids = r.heldout_episode_ids;
  json blocks = nullptr;
  if (r.blocks) {
    json list = json::array();
    for (std::size_t k = 0; k < r.blocks->blocks.size(); ++k) {
      const HeldoutBlock& b = r.blocks->blocks[k];
      list.push_back({{"block", k},
                      {"heldout", b.heldout},
                      {"first", b.first},
                      {"last", b.end - 1},
                      {"t_start", b.t_start},
                      {"t_end", b.t_end},
                      {"used_first", b.used_first},
                      {"used_last", b.used_end - 1},
                      {"dropped", b.samples() - b.used_samples()}});
    }
    blocks = {{"episode", r.blocks->episode_id},
              {"samples", r.blocks->samples},
              {"count", r.blocks->blocks.size()},
              {"heldout", r.blocks->heldout()},
              {"gap", r.blocks->gap},
              {"gap_time", r.blocks->gap * r.blocks->dt},
              {"blocks", list}};
  }
  return {{"system", r.system},
          {"samples", r.samples},
          {"dt", r.dt},
          {"heldout_episodes", heldout_ids},
          {"heldout_blocks", blocks},
          {"consistent", r.consistent},
          {"states", states},
          {"k_step", k_step},
          {"whiteness", whiteness_json(r)},
          {"free_run", free_run_json(r)},
          {"relevance", relevance},
          {"sensitivity", sensitivity},
          {"where", where_json(r)},
          {"gp_explained", r.gp_explained_total},
          {"criterion",
           {{"name", r.criterion->name()},
            {"window", r.criterion->window()},
            {"instruments", instruments_json(r)},
            {"weights", channel_weights_json(r)},
            {"restarts", r.window_restarts},
            {"starts", r.criterion->starts().empty() ? json(nullptr) : json(r.criterion->starts())},
            {"chosen_by", r.criterion_reason.empty() ? "user" : "data"},
            {"excluded", r.criterion_excluded},
            {"reason", r.criterion_reason.empty() ? json(nullptr) : json(r.criterion_reason)}}},
          {"ranking", ranking},
          {"verdict", verdict},
          {"excluded", r.excluded},
          {"on_request", r.on_request},
          {"model", model_file_text(r.model)},
          {"added", added},
          {"refitted", refitted},
          {"selection", selection},
          {"comparison", comparison},
          {"model_next", model_file_text(r.model_next)},
          {"non_finite_predictions", r.non_finite_predictions},
          {"model_diverges", r.model_diverges},
          {"divergence",
           {{"bound", kDivergedStateMagnitude},
            {"one_step", {{"diverged", r.non_finite_predictions}, {"transitions", r.samples}}},
            {"k_step", {{"diverged", r.diverged_windows}, {"windows", r.windows}}}}}};
}

}  // namespace gpilqg::diagnosis
