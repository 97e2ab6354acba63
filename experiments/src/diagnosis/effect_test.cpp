#include "gpilqg/experiments/diagnosis/effect_test.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gpilqg/experiments/diagnosis/student_t.hpp"

namespace gpilqg::diagnosis {

bool interval_contains_null(const EffectValues& v) {
  if (v.null_value.size() != v.estimate.size() || v.ci_low.size() != v.estimate.size()) return false;
  return (v.ci_low.array() <= v.null_value.array()).all() && (v.null_value.array() <= v.ci_high.array()).all();
}

namespace {

bool listed(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string interval_reason(const EffectValues& v) {
  std::string values;
  for (Eigen::Index j = 0; j < v.estimate.size(); ++j)
    values += fmt::format("{}{} = {:.4g} [{:.4g}, {:.4g}] holds {:.4g}", j == 0 ? "" : ", ",
                          v.parameters[static_cast<std::size_t>(j)].name, v.estimate(j), v.ci_low(j), v.ci_high(j),
                          v.null_value(j));
  return fmt::format("the 95% interval of '{}' contains its value without it ({}): not distinguishable from its absence",
                     v.effect, values);
}

}  // namespace

JudgedShare judged_share(const EffectFit& fit, const std::vector<std::string>& known, const std::string& residual) {
  std::vector<int> channels;
  const auto add = [&](const std::string& name, const std::vector<int>& acts_on) {
    if (!listed(known, name)) channels.insert(channels.end(), acts_on.begin(), acts_on.end());
  };
  add(fit.effect, fit.acts_on);
  for (const EffectValues& v : fit.refitted) add(v.effect, v.acts_on);
  std::sort(channels.begin(), channels.end());
  channels.erase(std::unique(channels.begin(), channels.end()), channels.end());
  const auto all = fit.heldout_channel_before.cols();
  if (static_cast<Eigen::Index>(channels.size()) == all) channels.clear();
  // On every channel the share is the fit's own (heldout_share of all channels, step 4).
  JudgedShare out{channels.empty() ? HeldoutShare{fit.explained, fit.explained_ci, fit.z_score}
                                   : heldout_share(fit, channels),
                  residual, channels};
  if (!channels.empty())
    out.what = fmt::format("{} on the {} of {} channels {} act{} on", residual, channels.size(), all,
                           fit.refitted.empty() ? "it" : "the new members", fit.refitted.empty() ? "s" : "");
  return out;
}

EffectTestResult test_effect(const EffectFit& fit, const EffectTestThresholds& t,
                             const std::vector<std::string>& already_in_model,
                             const std::vector<std::string>& accepted_before) {
  EffectTestResult result;
  if (!fit.identifiable) {
    // A joint fit is identifiable as a whole or not at all: name the set, whose not_identifiable text
    // names the parameter at fault (not necessarily the lead's).
    std::string who = fmt::format("'{}'", fit.effect);
    if (!fit.refitted.empty()) {
      who = "the set of '" + fit.effect + "'";
      for (const EffectValues& v : fit.refitted) who += ", '" + v.effect + "'";
    }
    result.reason = fmt::format("{} is not identifiable on these data{}", who,
                                fit.not_identifiable.empty() ? std::string() : ": " + fit.not_identifiable);
    return result;
  }
  std::vector<EffectValues> members{own_values(fit)};
  members.insert(members.end(), fit.refitted.begin(), fit.refitted.end());
  for (const EffectValues& v : members) {
    if (listed(already_in_model, v.effect) || !interval_contains_null(v)) continue;
    result.reason = interval_reason(v);
    return result;
  }
  std::vector<std::string> known = already_in_model;
  known.insert(known.end(), accepted_before.begin(), accepted_before.end());
  const JudgedShare judged = judged_share(fit, known, "the held-out residual");
  const HeldoutShare& s = judged.share;
  if (s.explained < t.min_explained || s.z_score < t.min_z) {
    result.reason = fmt::format("{}; a finding needs at least {:.0f}% and z >= {:g}",
                                share_text(s.explained, s.explained_ci, s.z_score, judged.what), 100.0 * t.min_explained,
                                t.min_z);
    return result;
  }
  result.accepted = true;
  return result;
}

std::string share_text(double explained, double explained_ci, double z, const std::string& what) {
  // A share that rounds to +0.0% or below removes nothing worth a number.
  if (explained < 0.0005)
    return fmt::format("removes nothing of {} (it {} {:.2g}%, z = {:.1f})", what, explained < 0.0 ? "adds" : "removes",
                       100.0 * std::abs(explained), z);
  return fmt::format("removes {:.1f}% +- {:.1f}% of {} (z = {:.1f})", 100.0 * explained, 100.0 * explained_ci, what, z);
}

HeldoutComparison compare_heldout(const EffectFit& a, const EffectFit& b) {
  HeldoutComparison c;
  const Eigen::Index K = a.heldout_batch_before.size();
  if (K < 2 || b.heldout_batch_before.size() != K || a.heldout_batch_reduction.size() != K ||
      b.heldout_batch_reduction.size() != K || a.heldout_batch_before != b.heldout_batch_before)
    return c;
  // The batches that hold equations: those of either fit (batches_with_equations on the difference).
  const auto [batch_before, d] =
      batches_with_equations(a.heldout_batch_before, a.heldout_batch_reduction - b.heldout_batch_reduction);
  const double before = batch_before.sum();
  const auto live = batch_before.size();
  if (!(before > 0.0) || live < 2) return c;
  c.comparable = true;
  c.difference = d.sum() / before;
  const double spread = (d - c.difference * batch_before).squaredNorm();
  const auto k = static_cast<double>(live);
  c.difference_ci = batch_half_width(std::sqrt(k / (k - 1.0) * spread) / before, static_cast<int>(live));
  return c;
}

}  // namespace gpilqg::diagnosis
