#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"

namespace gpilqg::diagnosis {

namespace {

std::string percent(double fraction) { return fmt::format("{:.1f}%", 100.0 * fraction); }

std::string parameter_text(const std::vector<EffectParameter>& parameters, const Vector& estimate, const Vector& low,
                           const Vector& high, bool interval) {
  std::string out;
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    out += fmt::format("{}{} = {:.4g} {}", i == 0 ? "" : ", ", parameters[i].name, estimate(k), parameters[i].unit);
    if (interval) out += fmt::format(" [{:.4g}, {:.4g}]", low(k), high(k));
  }
  return out;
}

/// ", v0 = ..." for Coulomb friction (its smoothing velocity), else nothing.
std::string smoothing_text(double v0) { return v0 > 0.0 ? fmt::format(", v0 = {:.3g}", v0) : std::string(); }

std::string parameter_text(const EffectFit& f, bool interval) {
  return parameter_text(f.parameters, f.estimate, f.ci_low, f.ci_high, interval) + smoothing_text(f.smoothing);
}

std::string parameter_text(const EffectValues& v) {
  return parameter_text(v.parameters, v.estimate, v.ci_low, v.ci_high, true) + smoothing_text(v.smoothing);
}

std::string model_text(const ModelSpec& model) {
  std::string out = fmt::format("{} preset '{}'", model.system, to_string(model.preset));
  for (const auto& line : model.describe()) out += " + " + line;
  return out;
}

void compare_section(const DiagnosisReport& r, std::string& out) {
  out += "\n1. Compare: one-step prediction, fit on the increments x[t+1] - x[t]\n";
  out += fmt::format("   {:<10} {:>10} {:>11} {:>10} {:>8} {:>9}\n", "state", "rmse", "noise floor", "held-out", "fit %",
                     "GP finds");
  for (const StateScore& s : r.states)
    out += fmt::format("   {:<10} {:>10.3e} {:>11.3e} {:>10.3e} {:>8.1f} {:>9}{}\n", s.name, s.rmse, s.noise_floor,
                       s.heldout_rmse, s.fit_percent, percent(std::max(0.0, s.gp_explained)),
                       s.structured ? "  above the floor" : "");
  out += "   k-step open-loop prediction from measured states (rmse / fit % on the state):\n";
  for (const KStepScore& k : r.k_step) {
    out += fmt::format("   k = {:<3} {:>5} windows{}:", k.k, k.windows,
                       k.diverged > 0 ? fmt::format(" ({} diverged)", k.diverged) : std::string());
    for (std::size_t i = 0; i < r.state_names.size() && i < 6; ++i)
      out += fmt::format("  {} {:.2e}/{:.0f}", r.state_names[i], k.rmse(static_cast<Eigen::Index>(i)),
                         k.fit_percent(static_cast<Eigen::Index>(i)));
    out += r.state_names.size() > 6 ? "  ...\n" : "\n";
  }
  if (r.model_diverges) {
    out += fmt::format("   => the model diverges on the data: {} of {} one-step predictions and {} of {} k-step windows "
                       "(not finite or beyond |x| = {:g})\n",
                       r.non_finite_predictions, r.samples, r.diverged_windows, r.windows, kDivergedStateMagnitude);
  } else if (r.consistent) {
    out += "   => consistent with the measurements: every residual is at its noise floor\n";
  } else {
    std::string above;
    for (const StateScore& s : r.states)
      if (s.structured) above += (above.empty() ? "" : ", ") + s.name;
    out += above.empty() ? "   => not consistent with the measurements: the GP of (x, u) finds no structure, but an effect "
                           "removes a significant share of the held-out residual (section 3)\n"
                         : "   => not consistent with the measurements: " + above + " above the noise floor\n";
  }
}

/// A fit percent in a column of 9: fixed point, or exponent form when a simulation drifted far.
std::string fit_text(double fit) { return std::abs(fit) < 1e5 ? fmt::format("{:>9.1f}", fit) : fmt::format("{:>9.2e}", fit); }

/// At most 6 state columns, as wide as their names.
constexpr std::size_t kStateColumns = 6;

std::string state_header(const DiagnosisReport& r) {
  std::string out;
  for (std::size_t i = 0; i < std::min(kStateColumns, r.state_names.size()); ++i)
    out += fmt::format(" {:>9}", r.state_names[i]);
  return out + (r.state_names.size() > kStateColumns ? "  ..." : "");
}

/// What the held-out units are: blocks of one record, or episodes.
const char* unit_name(const DiagnosisReport& r) { return r.blocks ? "block" : "episode"; }

/// A single record's blocks (heldout_blocks.hpp): which are held out, and the gap.
void blocks_section(const DiagnosisReport& r, std::string& out) {
  const HeldoutBlocks& b = *r.blocks;
  out += fmt::format("data: one record (episode {}, {} samples, dt = {:.6g} s) cut into {} blocks, held-out blocks {}; "
                     "{} transitions used\n",
                     b.episode_id, b.samples, r.dt, b.blocks.size(), fmt::join(r.heldout_episode_ids, ", "), r.samples);
  out += fmt::format("   gap: the {} training samples ({:.4g} s) on either side of every held-out block are dropped, the "
                     "longest k-step window\n", b.gap, b.gap * b.dt);
  out += fmt::format("   {:<6} {:<9} {:>17} {:>25} {:>17}\n", "block", "role", "samples", "t [s]", "samples used");
  for (std::size_t k = 0; k < b.blocks.size(); ++k) {
    const HeldoutBlock& h = b.blocks[k];
    out += fmt::format("   {:<6} {:<9} {:>17} {:>25} {:>17}\n", k, h.heldout ? "held out" : "training",
                       fmt::format("{}..{}", h.first, h.end - 1), fmt::format("{:.6g}..{:.6g}", h.t_start, h.t_end),
                       fmt::format("{}..{}", h.used_first, h.used_end - 1));
  }
}

void whiteness_section(const DiagnosisReport& r, std::string& out) {
  const Whiteness& w = r.whiteness;
  if (w.states.empty()) return;
  out += fmt::format("\nWhiteness of the held-out residual (one-step, autocorrelation within {}s, lags 1..{}, N = {})\n",
                     unit_name(r), w.max_lag, w.samples);
  if (w.degrees_of_freedom == 0) {
    out += fmt::format("   no lag has a pair of samples within one {}: nothing to test\n", unit_name(r));
    return;
  }
  out += fmt::format("   95% band +-{:.3f}; white when the Ljung-Box Q <= chi2_{:.2f}({}) = {:.2f} (p >= {:g})\n", w.band,
                     1.0 - w.level, w.degrees_of_freedom, w.critical_value, w.level);
  out += fmt::format("   {:<10} {:>8} {:>13} {:>10} {:>7}  {}\n", "state", "rho(1)", "outside band", "Q", "p", "white");
  std::string coloured, noise_like;
  for (const StateWhiteness& s : w.states) {
    const double lag_one = w.max_lag >= 1 ? s.autocorrelation(1) : 0.0;
    out += fmt::format("   {:<10} {:>8.3f} {:>13} {:>10.4g} {:>7}  {}\n", s.name, lag_one,
                       fmt::format("{}/{}", s.outside_band, w.max_lag), s.ljung_box,
                       s.p_value < 0.001 ? std::string("<0.001") : fmt::format("{:.3f}", s.p_value), s.white ? "yes" : "no");
    if (s.white) continue;
    // rho(1) near -1/2: the one-step residual differences the noise of the measured state (whiteness.hpp).
    std::string& list = lag_one <= -0.35 ? noise_like : coloured;
    list += (list.empty() ? "" : ", ") + s.name;
  }
  if (coloured.empty() && noise_like.empty()) out += "   => white: no time structure left in the one-step residual\n";
  if (!coloured.empty()) out += "   => not white: " + coloured + " (the one-step errors are predictable from the past)\n";
  if (!noise_like.empty())
    out += "   => not white: " + noise_like + " with rho(1) near -1/2, the mark of noise on the measured state\n";
}

void free_run_section(const DiagnosisReport& r, std::string& out) {
  if (r.free_run.empty()) return;
  out += fmt::format("\nFree-run fit (k = inf) per held-out {}: simulated from the measured x[0] {}, fit % per state\n",
                     unit_name(r), r.control_names.empty() ? "(a passive system: no controls)" : "with the measured controls");
  out += fmt::format("   {:<8} {:<11}{}\n", unit_name(r), "model", state_header(r));
  for (const FreeRunEpisode& e : r.free_run) {
    bool first = true;
    for (const FreeRunTrajectory& m : e.models) {
      out += fmt::format("   {:<8} {:<11}", first ? std::to_string(e.id) : std::string(), m.model);
      first = false;
      for (Eigen::Index i = 0; i < std::min<Eigen::Index>(kStateColumns, m.fit_percent.size()); ++i)
        out += " " + fit_text(m.fit_percent(i));
      if (m.diverged && m.steps == 0)
        out += fmt::format("  (diverged at the first step, t = {:.3g} s: no fit)", e.t(1));
      else if (m.diverged)
        out += fmt::format("  (diverged after {} of {} steps, at t = {:.3g} s; fit over the steps before)", m.steps,
                           e.t.size() - 1, e.t(m.steps + 1));
      out += "\n";
    }
  }
}

void where_section(const DiagnosisReport& r, std::string& out) {
  out += "\n2. Where it fails\n";
  for (std::size_t i = 0; i < r.states.size(); ++i) {
    if (!r.states[i].structured) continue;
    const auto ii = static_cast<Eigen::Index>(i);
    // The input along which the binned residual varies most, and its worst bin.
    double best_ratio = 0.0;
    std::string region;
    for (const BinnedResidual& b : r.bins) {
      Eigen::Index hi = 0;
      const double top = b.rms.row(ii).maxCoeff(&hi);
      double low = top;
      for (Eigen::Index k = 0; k < b.rms.cols(); ++k)
        if (b.count[static_cast<std::size_t>(k)] > 0) low = std::min(low, b.rms(ii, k));
      const double ratio = low > 0.0 ? top / low : 0.0;
      if (ratio > best_ratio) {
        best_ratio = ratio;
        region = fmt::format("{} in [{:.3g}, {:.3g}]: rmse {:.2e} vs {:.2e} in the best bin", b.input, b.edges(hi),
                             b.edges(hi + 1), top, low);
      }
    }
    out += fmt::format("   {}: largest where {}\n", r.state_names[i], region);
    std::string relevance;
    std::vector<std::pair<double, std::string>> ranked;
    for (std::size_t j = 0; j < r.input_names.size(); ++j)
      ranked.emplace_back(r.relevance(ii, static_cast<Eigen::Index>(j)), r.input_names[j]);
    std::sort(ranked.rbegin(), ranked.rend());
    for (std::size_t j = 0; j < std::min<std::size_t>(3, ranked.size()); ++j)
      relevance += fmt::format("{}{} {:.2f}", j == 0 ? "" : ", ", ranked[j].second, ranked[j].first);
    out += fmt::format("      GP relevance (share of mean |dmu/dz| std(z)): {}\n", relevance);
    for (std::size_t j = 0; j < r.control_names.size(); ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      out += fmt::format("      cross-correlation with {}: max |rho| {:.3f}, 95% band {:.3f}{}\n", r.control_names[j],
                         r.xcorr.max_abs(ii, jj), r.xcorr.band(ii, jj),
                         r.xcorr.max_abs(ii, jj) > r.xcorr.band(ii, jj) ? " (significant)" : "");
    }
  }
  const int worst = worst_state(r);
  out += fmt::format("   {} residual RMSE per {}:", r.state_names[static_cast<std::size_t>(worst)], unit_name(r));
  for (Eigen::Index e = 0; e < r.episode_rms.rows(); ++e) out += fmt::format(" {:.2e}", r.episode_rms(e, worst));
  out += "\n";
}

void which_section(const DiagnosisReport& r, std::string& out) {
  if (r.model_diverges && r.ranking.empty())
    out += "\n3. Which effect is missing: not ranked, the model diverges on the data\n";
  if (r.ranking.empty()) return;
  const int worst = worst_channel(r);
  out += fmt::format("\n3. Which effect is missing (fitted on training {0}s, scored on held-out {0}s {1})\n", unit_name(r),
                     fmt::join(r.heldout_episode_ids, ", "));
  if (!r.excluded.empty())
    out += fmt::format("   excluded by --exclude (never ranked, searched or proposed): {}\n", fmt::join(r.excluded, ", "));
  if (!r.on_request.empty())
    out += fmt::format("   searched only on request (--include PATTERN), not ranked: {} candidates ({})\n",
                       r.on_request.size(), fmt::join(r.on_request, ", "));
  if (!r.criterion_reason.empty()) out += "   criterion chosen by the data (--criterion auto): " + r.criterion_reason + "\n";
  if (const std::string line = r.criterion->description(r.dt, r.window_restarts); !line.empty())
    out += "   " + line + "\n";
  if (!r.criterion_excluded.empty())
    out += fmt::format("   not candidates on this criterion ({}): {}\n", r.criterion->unidentifiable_reason(),
                       fmt::join(r.criterion_excluded, ", "));
  // Columns as wide as the longest name and parameter text (a MuJoCo model's effects have long names).
  std::size_t name_width = 24, parameter_width = 40;
  for (const RankedEffect& g : r.ranking) {
    name_width = std::max(name_width, g.fit.effect.size());
    parameter_width = std::max(parameter_width, parameter_text(g.fit, true).size());
    for (const EffectFit& a : g.aliases) {
      name_width = std::max(name_width, a.effect.size() + 6);  // "alias " takes 6 of the name's column
      parameter_width = std::max(parameter_width, parameter_text(a, true).size());
    }
  }
  out += fmt::format("   {:<3} {:<{}} {:<{}} {:>17} {:>24}\n", "#", "effect", name_width, "parameter [95% interval]",
                     parameter_width, "explained", "held-out rmse " + r.channel_names[static_cast<std::size_t>(worst)]);
  int rank = 1;
  std::string not_identifiable;
  for (const RankedEffect& g : r.ranking) {
    const EffectFit& f = g.fit;
    if (!f.identifiable) {
      not_identifiable += fmt::format("   - {}: {}\n", f.effect, f.not_identifiable);
      continue;
    }
    out += fmt::format("   {:<3} {:<{}} {:<{}} {:>8} +-{:>6} {:>11.3e} -> {:.3e}{}\n", rank++, f.effect, name_width,
                       parameter_text(f, true), parameter_width, percent(f.explained), percent(f.explained_ci),
                       f.heldout_rmse_before(worst), f.heldout_rmse_after(worst),
                       interval_contains_null(own_values(f)) ? "  (interval holds its value without it)"
                       : g.rival ? fmt::format("  (as good as #1 on the held-out rows: {} +- {})", percent(g.behind_first),
                                               percent(g.behind_first_ci))
                                 : "");
    for (const EffectFit& a : g.aliases)
      out += fmt::format("       alias {:<{}} {:<{}} {:>8}   (cannot be told apart on these data)\n", a.effect,
                         name_width - 6, parameter_text(a, true), parameter_width, percent(a.explained));
  }
  if (!not_identifiable.empty())
    out += "   not identifiable on these data (not ranked):\n" + not_identifiable;
}

void selection_section(const DiagnosisReport& r, std::string& out) {
  if (!r.selection) return;
  out += r.selection->method == SearchMethod::Subsets
             ? "\n3b. Several effects (--auto): the best set of each size on the held-out episodes, every set fitted jointly\n"
             : "\n3b. Several effects (--auto): forward selection, every step refitting the chosen effects jointly\n";
  int k = 1;
  // Judged on the channels of what the step adds (effect_test.hpp, test 3).
  const std::vector<JudgedShare> judged_shares = judged_step_shares(*r.selection, r.model, "the held-out residual left");
  // The effects of the step before (the model's own at first): a step may bring several new ones.
  std::vector<std::string> before = names_of_effects(model_effects(r.model, candidate_effects(r.model)));
  for (const SelectionStep& step : r.selection->steps) {
    const EffectFit& f = step.fit;
    const JudgedShare& judged = judged_shares[static_cast<std::size_t>(k - 1)];
    out += fmt::format("   step {}: + {}: {}\n", k++, f.effect, parameter_text(f, true));
    for (const EffectValues& v : f.refitted) {
      const bool had = std::find(before.begin(), before.end(), v.effect) != before.end();
      out += fmt::format("         {} {}: {}\n", had ? "  refitted" : "+", v.effect, parameter_text(v));
    }
    before = {f.effect};
    for (const EffectValues& v : f.refitted) before.push_back(v.effect);
    for (const std::string& name : step.removed)
      out += fmt::format("           removed {}\n", name);
    out += fmt::format("           {}; held-out rmse:",
                       share_text(judged.share.explained, judged.share.explained_ci, judged.share.z_score, judged.what));
    for (std::size_t i = 0; i < r.channel_names.size() && i < static_cast<std::size_t>(f.heldout_rmse_before.size()); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      if (f.heldout_rmse_before(ii) > 1.05 * f.heldout_rmse_after(ii))
        out += fmt::format(" {} {:.3e} -> {:.3e}", r.channel_names[i], f.heldout_rmse_before(ii), f.heldout_rmse_after(ii));
    }
    out += "\n";
  }
  out += "   stop: " + r.selection->stop_reason + "\n";
}

void add_section(const DiagnosisReport& r, std::string& out) {
  if (r.comparison.empty()) return;
  out += fmt::format("\n4. {} on the held-out {}s (effect = {})\n",
                     r.added.empty() && !r.selection ? "What adding it would do" : "Add it and watch the error fall",
                     unit_name(r), r.comparison_effect);
  for (const EffectFit& f : r.added) out += fmt::format("   added {}: {}\n", f.effect, parameter_text(f, true));
  for (const EffectValues& v : r.refitted) out += fmt::format("   refitted with them {}: {}\n", v.effect, parameter_text(v));
  std::vector<int> shown;
  for (std::size_t i = 0; i < r.states.size(); ++i)
    if (r.states[i].structured || r.comparison[0].heldout_rmse(static_cast<Eigen::Index>(i)) >
                                      1.05 * r.comparison[1].heldout_rmse(static_cast<Eigen::Index>(i)))
      shown.push_back(static_cast<int>(i));
  if (shown.empty()) shown.push_back(worst_state(r));
  out += fmt::format("   {:<15}", "model");
  for (int i : shown) out += fmt::format(" {:>12}", "rmse " + r.state_names[static_cast<std::size_t>(i)]);
  for (int i : shown) out += fmt::format(" {:>14}", "GP sf^2 " + r.state_names[static_cast<std::size_t>(i)]);
  out += "\n";
  for (const ModelScore& m : r.comparison) {
    out += fmt::format("   {:<15}", m.name);
    for (int i : shown) out += fmt::format(" {:>12.3e}", m.heldout_rmse(i));
    for (int i : shown) out += m.signal_variance.size() > 0 ? fmt::format(" {:>14.3e}", m.signal_variance(i)) : fmt::format(" {:>14}", "-");
    out += "\n";
  }
}

}  // namespace

std::string report_text(const DiagnosisReport& r) {
  std::string out = fmt::format("gpilqg diagnose: {}\n", model_text(r.model));
  if (!r.added.empty()) out += fmt::format("  (started from {})\n", model_text(r.model_before));
  if (r.blocks)
    blocks_section(r, out);
  else
    out += fmt::format("data: {} transitions, dt = {} s, held-out episodes {}\n", r.samples, r.dt,
                       fmt::join(r.heldout_episode_ids, ", "));
  compare_section(r, out);
  whiteness_section(r, out);
  where_section(r, out);
  which_section(r, out);
  selection_section(r, out);
  add_section(r, out);
  free_run_section(r, out);
  out += "\nverdict: " + r.verdict.status;
  if (!r.verdict.effects.empty()) {
    out += fmt::format(": {} (the set of 3b)", fmt::join(r.verdict.effects, ", "));
  } else if (r.verdict.effect) {
    out += fmt::format(": {} ({})", r.verdict.effect->effect, parameter_text(*r.verdict.effect, true));
    if (!r.verdict.aliases.empty()) out += fmt::format(", or its aliases {}", fmt::join(r.verdict.aliases, ", "));
  }
  if (!r.verdict.rivals.empty())
    out += fmt::format("; or as well {} (the held-out rows do not tell them apart)", fmt::join(r.verdict.rivals, ", "));
  out += "\n  " + r.verdict.reason + "\n";
  return out;
}

}  // namespace gpilqg::diagnosis
