#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/report_hdf5.hpp"

#include <chrono>
#include <ctime>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/core/utc_time.hpp"
#include "gpilqg/core/version.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"

namespace gpilqg::diagnosis {

namespace {

std::vector<double> row_major(const std::vector<std::vector<Vector>>& values) {
  std::vector<double> out;
  for (const auto& row : values)
    for (const Vector& v : row) out.insert(out.end(), v.data(), v.data() + v.size());
  return out;
}

std::vector<std::string> units_of(const std::vector<Quantity>& quantities) {
  std::vector<std::string> out;
  for (const Quantity& q : quantities) out.push_back(q.unit);
  return out;
}

/// The units of the states and controls (for the plots' axes), from the system's signature.
void write_units(Hdf5Writer& h5, const DiagnosisReport& r) {
  const SystemSignature signature = system_signature(r.system);
  if (signature.states.size() == r.state_names.size()) h5.attribute("/", "state_units", units_of(signature.states));
  if (signature.controls.size() == r.control_names.size()) h5.attribute("/", "control_units", units_of(signature.controls));
}

void write_data(Hdf5Writer& h5, const DiagnosisReport& r) {
  h5.write_matrix("/data/x", r.data.x);
  h5.write_matrix("/data/u", r.data.u);
  h5.write_matrix("/data/x_next", r.data.x_next);
  h5.write_vector("/data/t", r.data.t);
  h5.write_vector("/data/episode", r.data.episode);
  h5.write_vector("/data/heldout", std::vector<int>(r.data.heldout.begin(), r.data.heldout.end()));

  h5.write_matrix("/compare/predicted", r.predicted);
  h5.write_matrix("/compare/residual", r.residual);
  h5.write_matrix("/compare/gp_mean", r.gp.mean);
  h5.write_matrix("/compare/gp_std", r.gp.variance.cwiseSqrt());
  std::vector<double> rmse, floor, heldout, fit, structure;
  for (const StateScore& s : r.states) {
    rmse.push_back(s.rmse);
    floor.push_back(s.noise_floor);
    heldout.push_back(s.heldout_rmse);
    fit.push_back(s.fit_percent);
    structure.push_back(s.gp_explained);
  }
  h5.write_vector("/compare/states/rmse", rmse);
  h5.write_vector("/compare/states/noise_floor", floor);
  h5.write_vector("/compare/states/heldout_rmse", heldout);
  h5.write_vector("/compare/states/fit_percent", fit);
  h5.write_vector("/compare/states/gp_explained", structure);
  for (const KStepScore& k : r.k_step) {
    const std::string g = "/compare/k_" + std::to_string(k.k);
    h5.write_matrix(g + "/measured", k.predictions.measured);
    h5.write_matrix(g + "/predicted", k.predictions.predicted);
    h5.write_vector(g + "/episode", k.predictions.episode);
    h5.write_vector(g + "/start", k.predictions.start);
    h5.write_vector(g + "/rmse", k.rmse);
    h5.write_vector(g + "/fit_percent", k.fit_percent);
    h5.attribute(g, "k", static_cast<std::int64_t>(k.k));
    h5.attribute(g, "stride", static_cast<std::int64_t>(k.stride));
    h5.attribute(g, "windows", static_cast<std::int64_t>(k.windows));
    h5.attribute(g, "diverged", static_cast<std::int64_t>(k.diverged));
  }
}

void write_whiteness(Hdf5Writer& h5, const DiagnosisReport& r) {
  const Whiteness& w = r.whiteness;
  if (w.states.empty()) return;
  std::vector<int> lags, outside, white;
  for (int k = 0; k <= w.max_lag; ++k) lags.push_back(k);
  Matrix rho(static_cast<Eigen::Index>(w.states.size()), w.max_lag + 1);
  std::vector<double> q, p;
  for (std::size_t i = 0; i < w.states.size(); ++i) {
    const StateWhiteness& s = w.states[i];
    rho.row(static_cast<Eigen::Index>(i)) = s.autocorrelation.transpose();
    outside.push_back(s.outside_band);
    white.push_back(s.white ? 1 : 0);
    q.push_back(s.ljung_box);
    p.push_back(s.p_value);
  }
  h5.write_vector("/whiteness/lags", lags);
  h5.write_matrix("/whiteness/autocorrelation", rho);
  h5.write_vector("/whiteness/outside_band", outside);
  h5.write_vector("/whiteness/ljung_box_q", q);
  h5.write_vector("/whiteness/p_value", p);
  h5.write_vector("/whiteness/white", white);
  h5.attribute("/whiteness", "test", std::string("ljung_box"));
  h5.attribute("/whiteness", "band", w.band);
  h5.attribute("/whiteness", "samples", static_cast<std::int64_t>(w.samples));
  h5.attribute("/whiteness", "max_lag", static_cast<std::int64_t>(w.max_lag));
  h5.attribute("/whiteness", "level", w.level);
  h5.attribute("/whiteness", "degrees_of_freedom", static_cast<std::int64_t>(w.degrees_of_freedom));
  h5.attribute("/whiteness", "critical_value", w.critical_value);
}

/// A single record's blocks (heldout_blocks.hpp), sample ranges inclusive.
void write_blocks(Hdf5Writer& h5, const DiagnosisReport& r) {
  if (!r.blocks) return;
  std::vector<int> first, last, used_first, used_last, heldout;
  std::vector<double> t_start, t_end;
  for (const HeldoutBlock& b : r.blocks->blocks) {
    first.push_back(b.first);
    last.push_back(b.end - 1);
    used_first.push_back(b.used_first);
    used_last.push_back(b.used_end - 1);
    heldout.push_back(b.heldout ? 1 : 0);
    t_start.push_back(b.t_start);
    t_end.push_back(b.t_end);
  }
  h5.write_vector("/heldout_blocks/first", first);
  h5.write_vector("/heldout_blocks/last", last);
  h5.write_vector("/heldout_blocks/used_first", used_first);
  h5.write_vector("/heldout_blocks/used_last", used_last);
  h5.write_vector("/heldout_blocks/heldout", heldout);
  h5.write_vector("/heldout_blocks/t_start", t_start);
  h5.write_vector("/heldout_blocks/t_end", t_end);
  h5.attribute("/heldout_blocks", "episode", static_cast<std::int64_t>(r.blocks->episode_id));
  h5.attribute("/heldout_blocks", "samples", static_cast<std::int64_t>(r.blocks->samples));
  h5.attribute("/heldout_blocks", "gap", static_cast<std::int64_t>(r.blocks->gap));
  h5.attribute("/heldout_blocks", "gap_time", r.blocks->gap * r.blocks->dt);
}

void write_free_run(Hdf5Writer& h5, const DiagnosisReport& r) {
  if (r.free_run.empty()) return;
  std::vector<std::string> models;
  for (const FreeRunTrajectory& m : r.free_run.front().models) models.push_back(m.model);
  for (std::size_t j = 0; j < r.free_run.size(); ++j) {
    const FreeRunEpisode& e = r.free_run[j];
    const std::string g = "/free_run/" + std::to_string(j);
    h5.write_vector(g + "/t", e.t);
    h5.write_matrix(g + "/measured", e.measured);
    Matrix fit(static_cast<Eigen::Index>(e.models.size()), e.measured.cols());
    std::vector<int> steps, diverged;
    for (std::size_t k = 0; k < e.models.size(); ++k) {
      const FreeRunTrajectory& m = e.models[k];
      fit.row(static_cast<Eigen::Index>(k)) = m.fit_percent.transpose();
      steps.push_back(m.steps);
      diverged.push_back(m.diverged ? 1 : 0);
      h5.write_matrix(g + "/predicted/" + m.model, m.predicted);
    }
    h5.write_matrix(g + "/fit_percent", fit);
    h5.write_vector(g + "/steps", steps);
    h5.write_vector(g + "/diverged", diverged);
    h5.attribute(g, "id", static_cast<std::int64_t>(e.id));
    h5.attribute(g, "index", static_cast<std::int64_t>(e.index));
  }
  h5.attribute("/free_run", "models", models);
}

void write_where(Hdf5Writer& h5, const DiagnosisReport& r) {
  h5.write_matrix("/where/relevance", r.relevance);
  h5.write_matrix("/where/sensitivity", r.sensitivity);
  h5.write_matrix("/where/episode_rmse", r.episode_rms);
  for (const BinnedResidual& b : r.bins) {
    const std::string g = "/where/bins/" + b.input;
    h5.write_vector(g + "/edges", b.edges);
    h5.write_matrix(g + "/rmse", b.rms);
    h5.write_vector(g + "/count", b.count);
  }
  const int L = r.xcorr.max_lag;
  Vector lags(2 * L + 1);
  for (int k = -L; k <= L; ++k) lags(k + L) = k;
  h5.write_vector("/where/cross_correlation/lags", lags);
  const std::uint64_t n = r.xcorr.values.size(), m = n > 0 ? r.xcorr.values[0].size() : 0;
  h5.write_array("/where/cross_correlation/values", {n, m, static_cast<std::uint64_t>(2 * L + 1)}, row_major(r.xcorr.values));
  h5.write_matrix("/where/cross_correlation/band", r.xcorr.band);
}

void write_ranking(Hdf5Writer& h5, const DiagnosisReport& r) {
  const int state = worst_channel(r);
  h5.attribute("/ranking", "heldout_state", r.channel_names.empty() ? std::string() : r.channel_names[static_cast<std::size_t>(state)]);
  h5.attribute("/ranking", "criterion", r.criterion->name());
  h5.attribute("/ranking", "window", static_cast<std::int64_t>(r.criterion->window()));
  h5.attribute("/ranking", "window_restarts", static_cast<std::int64_t>(r.window_restarts));
  if (r.ranking.empty()) return;
  std::vector<std::string> effect, parameter, unit, aliases;
  std::vector<double> estimate, low, high, explained, explained_ci, z, before, after, null, identifiable, holds_null;
  for (const RankedEffect& e : r.ranking) {
    null.push_back(e.fit.null_value.size() > 0 ? e.fit.null_value(0) : 0.0);
    identifiable.push_back(e.fit.identifiable ? 1.0 : 0.0);
    holds_null.push_back(interval_contains_null(own_values(e.fit)) ? 1.0 : 0.0);
    effect.push_back(e.fit.effect);
    parameter.push_back(e.fit.parameters[0].name);
    unit.push_back(e.fit.parameters[0].unit);
    std::string list;
    for (const EffectFit& a : e.aliases) list += (list.empty() ? "" : ",") + a.effect;
    aliases.push_back(list);
    estimate.push_back(e.fit.estimate(0));
    low.push_back(e.fit.ci_low(0));
    high.push_back(e.fit.ci_high(0));
    explained.push_back(e.fit.explained);
    explained_ci.push_back(e.fit.explained_ci);
    z.push_back(e.fit.z_score);
    before.push_back(e.fit.heldout_rmse_before(state));
    after.push_back(e.fit.heldout_rmse_after(state));
  }
  h5.attribute("/ranking", "effect", effect);
  h5.attribute("/ranking", "parameter_name", parameter);
  h5.attribute("/ranking", "unit", unit);
  h5.attribute("/ranking", "aliases", aliases);
  h5.write_vector("/ranking/estimate", estimate);
  h5.write_vector("/ranking/ci_low", low);
  h5.write_vector("/ranking/ci_high", high);
  h5.write_vector("/ranking/explained", explained);
  h5.write_vector("/ranking/explained_ci", explained_ci);
  h5.write_vector("/ranking/z_score", z);
  h5.write_vector("/ranking/heldout_rmse_before", before);
  h5.write_vector("/ranking/heldout_rmse_after", after);
  h5.write_vector("/ranking/null_value", null);
  h5.write_vector("/ranking/identifiable", identifiable);
  h5.write_vector("/ranking/interval_holds_null", holds_null);
}

void write_add(Hdf5Writer& h5, const DiagnosisReport& r) {
  if (r.comparison.empty()) return;
  std::vector<std::string> names;
  Matrix rmse(static_cast<Eigen::Index>(r.comparison.size()), static_cast<Eigen::Index>(r.states.size()));
  Matrix variance(2, static_cast<Eigen::Index>(r.states.size()));
  int with_gp = 0;
  for (std::size_t k = 0; k < r.comparison.size(); ++k) {
    names.push_back(r.comparison[k].name);
    rmse.row(static_cast<Eigen::Index>(k)) = r.comparison[k].heldout_rmse.transpose();
    if (r.comparison[k].signal_variance.size() > 0 && with_gp < 2) variance.row(with_gp++) = r.comparison[k].signal_variance.transpose();
  }
  h5.write_matrix("/add/heldout_rmse", rmse);
  h5.write_matrix("/add/signal_variance", variance);
  h5.write_matrix("/add/residual_before", r.residual_base);
  h5.write_matrix("/add/residual_after", r.residual_after);
  h5.write_matrix("/add/relevance_before", r.relevance_base);
  h5.attribute("/add", "effect", r.comparison_effect);
  h5.attribute("/add", "model", names);
}

/// /selection (--auto): heldout_rmse ((steps + 1) x c: row 0 before the first step, row k after step k,
/// per channel of the criterion: the states, or the force components under inverse dynamics),
/// explained and z_score per step, and per step /selection/step_<k> with the joint values of every
/// effect of the model after that step (parameter names "<effect>.<parameter>", the added effect first).
void write_selection(Hdf5Writer& h5, const DiagnosisReport& r) {
  if (!r.selection) return;
  const auto& steps = r.selection->steps;
  const auto n = steps.empty() ? static_cast<Eigen::Index>(r.states.size()) : steps.front().fit.heldout_rmse_before.size();
  Matrix rmse(static_cast<Eigen::Index>(steps.size()) + 1, n);
  if (steps.empty()) {
    for (Eigen::Index i = 0; i < n; ++i) rmse(0, i) = r.states[static_cast<std::size_t>(i)].heldout_rmse;
  } else {
    rmse.row(0) = steps.front().fit.heldout_rmse_before.transpose();
  }
  std::vector<double> explained, z;
  std::vector<std::string> effects;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const EffectFit& f = steps[k].fit;
    rmse.row(static_cast<Eigen::Index>(k) + 1) = f.heldout_rmse_after.transpose();
    explained.push_back(f.explained);
    z.push_back(f.z_score);
    effects.push_back(f.effect);
    std::vector<EffectValues> values{own_values(f)};
    values.insert(values.end(), f.refitted.begin(), f.refitted.end());
    std::vector<std::string> names;
    std::vector<double> estimate, low, high;
    for (const EffectValues& v : values)
      for (std::size_t i = 0; i < v.parameters.size(); ++i) {
        const auto ii = static_cast<Eigen::Index>(i);
        names.push_back(v.effect + "." + v.parameters[i].name);
        estimate.push_back(v.estimate(ii));
        low.push_back(v.ci_low(ii));
        high.push_back(v.ci_high(ii));
      }
    const std::string group = fmt::format("/selection/step_{}", k + 1);
    h5.write_vector(group + "/estimate", estimate);
    h5.write_vector(group + "/ci_low", low);
    h5.write_vector(group + "/ci_high", high);
    h5.attribute(group, "parameter_name", names);
    h5.attribute(group, "effect", f.effect);
    if (!steps[k].removed.empty()) h5.attribute(group, "removed", steps[k].removed);
  }
  h5.write_matrix("/selection/heldout_rmse", rmse);
  h5.write_vector("/selection/explained", explained);
  h5.write_vector("/selection/z_score", z);
  h5.attribute("/selection", "effect", effects);
  if (!r.channel_names.empty()) h5.attribute("/selection", "channels", r.channel_names);
  h5.attribute("/selection", "stop_reason", r.selection->stop_reason);
  h5.attribute("/selection", "method", std::string(to_string(r.selection->method)));
}

}  // namespace

void write_report_hdf5(const std::filesystem::path& file, const DiagnosisReport& r) {
  write_atomically(file, [&](const std::filesystem::path& temporary) {
    Hdf5Writer h5(temporary);
    h5.attribute("/", "schema_version", std::int64_t{1});
    h5.attribute("/", "gpilqg_version", std::string(kVersionString));
    h5.attribute("/", "system", r.system);
    h5.attribute("/", "created", utc_timestamp());
    h5.attribute("/", "status", r.verdict.status);
    h5.attribute("/", "verdict_effect", r.verdict.effect ? r.verdict.effect->effect : std::string());
    h5.attribute("/", "consistent", std::int64_t{r.consistent ? 1 : 0});
    h5.attribute("/", "model_diverges", std::int64_t{r.model_diverges ? 1 : 0});
    h5.attribute("/", "diverged_predictions", static_cast<std::int64_t>(r.non_finite_predictions));
    h5.attribute("/", "diverged_windows", static_cast<std::int64_t>(r.diverged_windows));
    h5.attribute("/", "windows", static_cast<std::int64_t>(r.windows));
    h5.attribute("/", "model", model_file_text(r.model));
    h5.attribute("/", "model_next", model_file_text(r.model_next));
    h5.attribute("/", "report", report_json(r).dump());
    h5.attribute("/", "state_names", r.state_names);
    h5.attribute("/", "control_names", r.control_names);
    h5.attribute("/", "input_names", r.input_names);
    write_units(h5, r);
    write_data(h5, r);
    write_where(h5, r);
    write_ranking(h5, r);
    write_add(h5, r);
    write_selection(h5, r);
    write_whiteness(h5, r);
    write_free_run(h5, r);
    write_blocks(h5, r);
    h5.close();
  });
}

}  // namespace gpilqg::diagnosis
