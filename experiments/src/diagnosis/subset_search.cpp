#include "gpilqg/experiments/diagnosis/subset_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/core/fork_join.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "gpilqg/experiments/diagnosis/subset_exchange.hpp"
#include "gpilqg/experiments/diagnosis/velocity_scales.hpp"

namespace gpilqg::diagnosis {

namespace {

/// How many of the best linearised subsets of each size are refitted exactly.
constexpr int kExactFitsPerSize = 3;

/// A size is searched exhaustively when it has at most this many subsets: 14 candidates have 1,001
/// sets of four, a 7-joint arm's 100 candidates 161,700 sets of three and 3.9 million of four.
/// Screening costs K small solves per set (K <= 5 folds); beyond this a size grows greedily.
constexpr double kExhaustiveSets = 200000.0;

/// n choose k, as a double (it is only compared with kExhaustiveSets).
double binomial(int n, int k) {
  double out = 1.0;
  for (int i = 1; i <= k; ++i) out = out * static_cast<double>(n - k + i) / static_cast<double>(i);
  return out;
}

/// The (at most `count`) sets `base` + one more candidate with the least screening score, best first (the
/// greedy growth of a size too large to search exhaustively: forward selection on the
/// cross-validated linearised fits, as FROLS grows its model term by term).
std::vector<std::vector<int>> grown_subsets(const LinearisedFits& fits, const std::vector<int>& base, int count,
                                            const std::vector<std::vector<bool>>& forbidden) {
  std::vector<std::pair<double, std::vector<int>>> best;
  for (int c = 0; c < fits.size(); ++c) {
    if (std::find(base.begin(), base.end(), c) != base.end()) continue;
    bool allowed = !forbidden[static_cast<std::size_t>(c)][static_cast<std::size_t>(c)];
    for (int b : base) allowed = allowed && !forbidden[static_cast<std::size_t>(b)][static_cast<std::size_t>(c)];
    if (!allowed) continue;
    std::vector<int> grown = base;
    grown.push_back(c);
    best.emplace_back(fits.screening_left(grown), std::move(grown));
  }
  std::sort(best.begin(), best.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  if (static_cast<int>(best.size()) > count) best.resize(static_cast<std::size_t>(count));
  std::vector<std::vector<int>> out;
  for (auto& [left, set] : best) out.push_back(std::move(set));
  return out;
}

bool declared_same(const SystemEntry& entry, const std::string& a, const std::string& b) {
  for (const auto& group : entry.same_physics)
    if (std::find(group.begin(), group.end(), a) != group.end() && std::find(group.begin(), group.end(), b) != group.end())
      return true;
  return false;
}

/// The `count` subsets of size k with the least cross-validated linearised training residual
/// (LinearisedFits::screening_left: the held-out rows do not screen), best first.
std::vector<std::vector<int>> best_subsets(const LinearisedFits& fits, int k, int count,
                                           const std::vector<std::vector<bool>>& forbidden) {
  std::vector<std::pair<double, std::vector<int>>> best;
  std::vector<int> subset(static_cast<std::size_t>(k));
  const int n = fits.size();
  // Lexicographic enumeration of the k-subsets of 0..n-1.
  for (int i = 0; i < k; ++i) subset[static_cast<std::size_t>(i)] = i;
  while (k <= n) {
    bool allowed = true;
    for (int a = 0; a < k && allowed; ++a)
      for (int b = a; b < k && allowed; ++b)
        allowed = !forbidden[static_cast<std::size_t>(subset[static_cast<std::size_t>(a)])]
                            [static_cast<std::size_t>(subset[static_cast<std::size_t>(b)])];
    if (allowed) {
      const double left = fits.screening_left(subset);
      if (static_cast<int>(best.size()) < count || left < best.back().first) {
        best.emplace_back(left, subset);
        std::sort(best.begin(), best.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        if (static_cast<int>(best.size()) > count) best.pop_back();
      }
    }
    int i = k - 1;
    while (i >= 0 && subset[static_cast<std::size_t>(i)] == n - k + i) --i;
    if (i < 0) break;
    ++subset[static_cast<std::size_t>(i)];
    for (int j = i + 1; j < k; ++j) subset[static_cast<std::size_t>(j)] = subset[static_cast<std::size_t>(j - 1)] + 1;
  }
  std::vector<std::vector<int>> out;
  for (auto& [left, s] : best) out.push_back(std::move(s));
  return out;
}

/// The screening columns of Coulomb candidate `name` at the smoothing velocity `v0` an accepted set
/// fitted for it (joint_smoothing). A candidate's own fit alone puts its width at the top of the grid
/// when the effects still missing (a sensor's offset, a link's mass) leave a residual that grows with
/// the speed: a saturating viscous friction. Screened at that width, the Coulomb member already
/// stands for its joint's viscous friction, and the growth never takes the viscous term, even after
/// the set has found the switch's own width. Not for an effect of the model itself, whose width also
/// changes the base residual the columns are taken around.
void follow_width(LinearisedFits& fits, FitContext& screening, const std::vector<RefitEffect>& present,
                  const std::string& name, double v0) {
  const auto width = screening.model.smoothing.find(name);
  if (width != screening.model.smoothing.end() && width->second == v0) return;
  if (std::any_of(present.begin(), present.end(), [&](const RefitEffect& r) { return r.effect->name == name; })) return;
  screening.model.smoothing[name] = v0;
  for (int c = 0; c < fits.size(); ++c)
    if (fits.names()[static_cast<std::size_t>(c)] == name) fits.relinearise(c, screening);
}

}  // namespace

Selection select_subsets(const FitContext& context, const SelectionOptions& o, std::vector<RankedEffect> first) {
  if (context.data == nullptr) throw std::invalid_argument("select_subsets: no data");
  const SystemEntryPtr system = find_system(context.model.system);
  // Candidates; a Coulomb entry is replaced (in place: `present` points into it) when its smoothing
  // velocity is fitted again inside a set.
  std::vector<LibraryEffect> candidates = candidate_effects(context.model);
  const std::vector<RefitEffect> present = model_effects(context.model, candidates);
  std::vector<RankedEffect> ranking =
      first.empty() ? rank_effects(context, o.alias_gain, o.progress, present, o.threads) : std::move(first);

  // Every candidate fitted alone (aliases included), linearised around M_0.
  std::vector<EffectFit> singles;
  for (const RankedEffect& r : ranking) {
    singles.push_back(r.fit);
    singles.insert(singles.end(), r.aliases.begin(), r.aliases.end());
  }
  // Columns kept: the screening follows the smoothing velocities the accepted sets fit (below).
  LinearisedFits fits(context, singles, present, o.threads, true);
  FitContext screening_context = context;  // its model holds the smoothing velocities the columns have
  const auto n = static_cast<std::size_t>(fits.size());
  std::vector<std::vector<bool>> forbidden(n, std::vector<bool>(n, false));
  // forbidden[a][b]: a and b never in one set (declared the same physics); forbidden[a][a]: a in no set
  // (its fit alone is not identifiable: LinearisedFits gives it no columns, so a set holding it would
  // screen as the set without it and carry a member the data do not see).
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b)
      forbidden[a][b] = a == b ? !singles[a].identifiable : declared_same(*system, singles[a].effect, singles[b].effect);

  const MayJoin may_join = [&](int a, int b) {
    return !forbidden[static_cast<std::size_t>(a)][static_cast<std::size_t>(b)];
  };

  Selection S;
  S.method = SearchMethod::Subsets;
  S.model = context.model;
  FitContext accepted_context = context;  // model stays M_0; residual becomes the accepted model's
  FitContext widths_context = context;    // the widths of a set's Coulomb members: on every thread
  widths_context.threads = o.threads;
  std::vector<std::string> accepted;      // the members of the accepted set
  std::string last_rejection, stop_growing;
  std::vector<int> screened;  // the best screened set of the size before
  int searched = 0, exhaustive_up_to = 0;
  for (int k = 1; k <= std::min<int>(o.max_steps, static_cast<int>(n)); ++k) {
    // 2. The best linearised subsets of size k: all of them up to max_subset while a size has at most
    // kExhaustiveSets sets, else the best set of size k - 1 grown by one candidate, as long as that
    // lowers the cross-validated screening score. Refitted exactly against the accepted model.
    const bool exhaustive = k <= o.max_subset && binomial(static_cast<int>(n), k) <= kExhaustiveSets;
    if (!exhaustive && k > 1 && screened.empty()) break;
    std::vector<std::vector<int>> sets;
    std::vector<Exchange> exchanges;
    if (exhaustive) {
      sets = best_subsets(fits, k, kExactFitsPerSize, forbidden);
    } else {
      // The growth of the least screening score among those that lower it by more than its standard
      // error: the best score alone may come from a reduction the folds disagree on, while the next
      // one's is consistent. A candidate that fits noise does not pass by chance as often as a test at
      // one standard error would: its fit on the other folds predicts nothing on the fold left out, so
      // it raises the cross-validated score on most folds. A size the held-out rows do not accept does
      // not stop the growth (a member that removes too little alone is judged again beside the next).
      const std::vector<std::vector<int>> grown = grown_subsets(fits, screened, fits.size(), forbidden);
      const std::vector<double> before = fits.screening_folds(screened);
      for (const std::vector<int>& set : grown)
        if (k == 1 || lowers_by_more_than_its_error(before, fits.screening_folds(set))) {
          sets.push_back(set);
          break;
        }
      // Then members taken earlier as proxies of effects now in the set are exchanged for the
      // candidates the data prefer in their place (sequential replacement, subset_exchange.hpp).
      if (!sets.empty())
        sets.front() = exchanged([&](const std::vector<int>& set) { return fits.screening_folds(set); }, fits.size(),
                                 sets.front(), may_join, k, &exchanges);
      if (sets.empty() && !grown.empty())
        stop_growing = fmt::format("; none of the {} sets of {} grown from the best of {} lowers the cross-validated "
                                   "screening score by more than its standard error",
                                   grown.size(), k, k - 1);
    }
    if (sets.empty()) break;
    screened = sets.front();
    searched = k;
    if (exhaustive) exhaustive_up_to = k;
    if (o.progress && !exhaustive)
      o.progress(fmt::format("sets of {}: grown from the best set of {} (too many to search them all){}", k, k - 1,
                             exchanges.empty() ? ""
                             : static_cast<int>(exchanges.size()) == k
                                 ? fmt::format(", then members exchanged (the most at this size, {}):", k)
                                 : std::string(", then members exchanged:")));
    for (const Exchange& e : exchanges)
      if (o.progress)
        o.progress(fmt::format("  {} -> {}", singles[static_cast<std::size_t>(e.out)].effect,
                               singles[static_cast<std::size_t>(e.in)].effect));
    // The sets' exact fits are independent: o.threads at once, then compared in the order of `sets`.
    std::vector<EffectFit> exact(sets.size());
    std::atomic<std::size_t> next{0};
    ForkJoin workers;
    const int at_once = std::max(1, std::min<int>(o.threads, static_cast<int>(sets.size())));
    // The threads the sets leave idle evaluate each fit's model at once (a grown size fits one set,
    // and so do the backward check and the widths' refit below).
    accepted_context.threads = std::max(1, o.threads / at_once);
    workers.run(at_once, [&](int, int) {
      for (std::size_t s = next++; s < sets.size(); s = next++) {
        const std::vector<int>& subset = sets[s];
        const EffectFit& lead = singles[static_cast<std::size_t>(subset.front())];
        std::vector<RefitEffect> rest;
        for (std::size_t i = 1; i < subset.size(); ++i) {
          const EffectFit& member = singles[static_cast<std::size_t>(subset[i])];
          rest.push_back({&named(candidates, member.effect), member.estimate});
        }
        rest.insert(rest.end(), present.begin(), present.end());
        exact[s] = fit_jointly(named(candidates, lead.effect), rest, accepted_context, lead.estimate);
      }
    });
    EffectFit best;
    bool have = false;
    for (EffectFit& fit : exact) {
      // Chosen on the training rows (sets of one size, one start): the held-out rows only judge.
      if (!have || fit.training_objective_after < best.training_objective_after) best = std::move(fit);
      have = true;
    }
    if (!have) break;
    std::vector<std::string> members{best.effect};
    for (const EffectValues& v : best.refitted) members.push_back(v.effect);
    const std::string names = fmt::format("{}", fmt::join(members, ", "));
    // The share of what the accepted model leaves, on the channels the members it adds act on
    // (effect_test.hpp, test 3).
    const std::vector<std::string> in_m0 = names_of_effects(present);
    std::vector<std::string> known = in_m0;
    known.insert(known.end(), accepted.begin(), accepted.end());
    const JudgedShare judged = judged_share(best, known, "the held-out residual left");
    const HeldoutShare& share = judged.share;
    if (o.progress)
      o.progress(fmt::format("best subset of {}: {} {}", k, names,
                             share_text(share.explained, share.explained_ci, share.z_score, judged.what)));
    // 3. Accepted when it is a finding against the accepted model (effect_test.hpp): identifiable,
    // every new member's interval excluding its value without it, a significant and not negligible share.
    const EffectTestThresholds thresholds{o.min_explained, o.min_z};
    if (!best.identifiable || share.explained < o.min_explained || share.z_score < o.min_z) {
      last_rejection = fmt::format(
          "the best set of {} ({}) is not accepted: {}", k, names,
          best.identifiable ? fmt::format("it {}; a larger set needs at least {:.0f}% and z >= {:g}",
                                          share_text(share.explained, share.explained_ci, share.z_score, judged.what),
                                          100.0 * o.min_explained, o.min_z)
                            : test_effect(best, thresholds, in_m0).reason);
      continue;
    }
    std::vector<std::string> removed;
    best = without_redundant(best, context, accepted_context, candidates, removed);
    // The Coulomb members' smoothing velocities, fitted inside the set; the set refitted at them.
    bool rescaled = false;
    for (const auto& [name, v0] : joint_smoothing(widths_context, best)) {
      for (LibraryEffect& e : candidates)
        if (e.name == name && e.smoothing && e.smoothing->width != v0) {
          e = with_smoothing(e, v0);
          rescaled = true;
        }
      follow_width(fits, screening_context, present, name, v0);
    }
    if (rescaled) {
      std::vector<RefitEffect> rest;
      for (const EffectValues& v : best.refitted) rest.push_back({&named(candidates, v.effect), v.estimate});
      best = fit_jointly(named(candidates, best.effect), rest, accepted_context, best.estimate);
    }
    // The backward check may leave the accepted set itself, or a set no better than it.
    std::vector<std::string> kept{best.effect};
    for (const EffectValues& v : best.refitted) kept.push_back(v.effect);
    std::sort(kept.begin(), kept.end());
    std::vector<std::string> before = accepted;
    std::sort(before.begin(), before.end());
    const EffectTestResult finding = test_effect(best, thresholds, in_m0, accepted);
    if (kept == before || !finding.accepted) {
      last_rejection = fmt::format(
          "the best set of {} ({}) comes to {} after dropping members whose intervals contain their values without "
          "them, which {}",
          k, names, fmt::join(kept, ", "),
          finding.accepted ? "is the set accepted before" : "is not accepted: " + finding.reason);
      continue;
    }
    // Removed: in the previously accepted set, absent from this one. A member of this size's candidate
    // set that the backward check dropped was never in the model, so it is not "removed".
    std::vector<std::string> now{best.effect};
    for (const EffectValues& v : best.refitted) now.push_back(v.effect);
    removed.clear();
    for (const std::string& name : accepted)
      if (std::find(now.begin(), now.end(), name) == now.end()) removed.push_back(name);
    // The lead of the step is an effect new in this set, when there is one.
    if (std::find(accepted.begin(), accepted.end(), best.effect) != accepted.end()) {
      for (std::size_t i = 0; i < best.refitted.size(); ++i) {
        const std::string& name = best.refitted[i].effect;
        if (std::find(accepted.begin(), accepted.end(), name) != accepted.end()) continue;
        const bool from_m0 = std::any_of(present.begin(), present.end(), [&](const RefitEffect& r) { return r.effect->name == name; });
        if (from_m0) continue;
        const EffectValues lead = own_values(best), swap = best.refitted[i];
        best.refitted[i] = lead;
        best = led_by(std::move(best), swap);
        break;
      }
    }
    SelectionStep step{best, model_after(context.model, best, candidates), S.steps.empty() ? ranking : std::vector<RankedEffect>{},
                       removed};
    accepted.clear();
    for (const std::string& name : now)
      if (std::find(removed.begin(), removed.end(), name) == removed.end()) accepted.push_back(name);
    accepted_context.residual = criterion_residual(step.model, context);
    S.model = step.model;
    S.steps.push_back(std::move(step));
  }
  // A size is grown instead of searched when it is beyond max_subset or has too many sets (kExhaustiveSets).
  S.stop_reason = searched == exhaustive_up_to
                      ? fmt::format("every set of up to {} of the {} candidates searched", searched, n)
                      : fmt::format("every set of up to {} of the {} candidates searched, then sets grown one effect at a "
                                    "time up to {}",
                                    exhaustive_up_to, n, searched);
  S.stop_reason += stop_growing;
  if (!last_rejection.empty()) S.stop_reason += "; " + last_rejection;
  if (S.steps.empty()) S.rejected = std::move(ranking);
  return S;
}

}  // namespace gpilqg::diagnosis
