#pragma once
/// @file subset_search.hpp
/// Several missing effects in one call (`gpilqg diagnose --auto`, the default search): the best subset
/// of the candidates of each size up to four, scored on held-out data.
///
/// Forward selection adds the effect that is best alone, so it cannot find a set whose members are
/// weak alone: on a drive with viscous friction, Coulomb friction and a constant force, an actuator
/// gain that is a fair proxy for all three is taken first and the search stops. Every subset is
/// scored instead, the approach of best-subset regression (Furnival and Wilson's leaps and bounds
/// enumerate the same space), with held-out episodes as the criterion rather than an information
/// criterion (effect_selection.hpp says why):
///
///  1. every candidate is fitted alone (rank_effects: step 1 of the verdict) and linearised around
///     M_0 (linearised_fits.hpp), with the effects M_0 has refitted in every fit;
///  2. for k = 1 .. max_subset every subset S of k candidates, except those holding two effects the
///     system declares the same physics, is screened by the cross-validated residual its linearised
///     joint fit leaves on the training rows (LinearisedFits::screening_left: the held-out rows do not
///     screen); the three best of each size are refitted exactly (fit_jointly, starting from each
///     member's value fitted alone), the one of the least training objective is kept and scored on the
///     held-out rows against the model accepted so far (M_0 at first): the share of its held-out
///     residual it removes and the batch-means z score;
///  3. size k is accepted when that set is a finding (effect_test.hpp) against the accepted model:
///     at least min_explained (5%) of what it leaves with z >= min_z (3), identifiable, and, after the
///     backward check (a member whose joint interval contains its value without it is dropped and the
///     rest refitted), every new member's interval excluding that value; that set becomes the accepted
///     model. A size that is not accepted does not stop the search: a larger set can still be better;
///  4. the last accepted set is the result. The path has one step per accepted size, naming the
///     effects new in it and (as `removed`) those of the previous set it no longer holds.
///
/// Beyond max_subset, or where a size has more than 200,000 sets (a 7-joint arm's library of about 100
/// candidates has 3.9 million sets of four), the best screened set of the size before is grown by the
/// one candidate that lowers the screening score most (forward selection on the linearised fits, as
/// FROLS grows its model term by term) by more than the standard error of that reduction over the
/// folds (the one-standard-error rule; when the least score fails it, the next growth that passes),
/// then every member is open to exchange for a candidate outside the set while an exchange lowers the
/// score by more than its standard error, at most k exchanges at size k (sequential replacement,
/// subset_exchange.hpp: a member grown in early as the proxy of effects not yet in the set gives way to
/// them), refitted exactly and judged like the others; growth stops when no growth passes that rule,
/// or at max_steps effects. A size the held-out test does not accept does not stop it. So a set of
/// 14 frictions on 7 joints is reachable, at the cost of one exact joint fit per size.
///
/// The screening follows the smoothing velocities. A Coulomb candidate is linearised at the width its
/// fit alone chose (velocity_scales.hpp); an accepted set fits its Coulomb members' widths again
/// (joint_smoothing), and from then on those members are screened at the set's widths
/// (LinearisedFits::relinearise). Alone, with a sensor's offset or a link's mass still missing, a dry
/// friction's width can take the top of the grid (on the 7-joint arm as built, joint 1's 0.10 rad/s,
/// against 0.025 in the set): a saturating viscous friction, screened as such, beside which the joint's
/// own viscous friction never lowers the score.
///
/// The linearised scores cost one small solve per subset, so the exact fits (a few per size) are
/// what the search costs beyond the ranking. The forward selection stays available, and
/// docs/diagnosis.md compares both on the multi-effect test sets.

#include "gpilqg/experiments/diagnosis/effect_selection.hpp"

namespace gpilqg::diagnosis {

/// The search above; `first` is step 1's ranking when the caller already has it (rank_effects on
/// `context` with refit = model_effects(M_0)).
Selection select_subsets(const FitContext& context, const SelectionOptions& options, std::vector<RankedEffect> first = {});

}  // namespace gpilqg::diagnosis
