#pragma once
/// @file effect_test.hpp
/// The one test that decides whether a fitted effect, or a set of effects fitted jointly, is a
/// finding. Every place that accepts an effect uses it: the verdict, each step of `--auto` (both
/// searches), the backward check, and the evidence that a residual the GP calls noise is not at its
/// floor (an input delay).
///
/// An effect (or a set) is accepted when all three hold:
///
///  1. **Identifiable.** The data determine its parameters: the regressor is not zero (nor, where it
///     is a finite difference of the model, at the level of rounding: a change of the parameter's
///     typical size moves the predictions by more than kRoundingLevel of the model's own motion), the
///     Gauss-Newton covariance is finite, and no parameter moved further from its value without the
///     effect than kRunawayFactor (100) times its scale on these data (EffectFit::scale). An
///     armature of 2.7e21 kg m^2 on a wrist, or a link of 318 kg on an arm of 3 kg links, is a fit
///     that ran away along a direction the data barely see; its z score and zero-width interval say
///     nothing. A quantity that cannot be zero (a mass: EffectParameter::strictly_positive) is measured
///     against its own value too: when only a change of more than kRunawayFactor times that value
///     moves the predictions as much as the model does, the data cannot weigh it (a body's mass in a
///     free swing, where MuJoCo scales the inertia with it and the motion does not change at all).
///     Such fits are reported as not identifiable and never ranked.
///  2. **Its interval excludes the value without it.** The null hypothesis of an effect is the value
///     it has in the model it is added to (EffectFit::null_value: a force of 0, a gain of 1, the
///     model's own parameter, no delay). An effect whose 95% interval contains that value in every
///     parameter is not significant, whatever its held-out z score: the training data do not
///     distinguish it from its absence. For a set, every member the model does not have must pass.
///  3. **It removes a large and significant share of the held-out residual where it acts:**
///     explained >= min_explained with a batch-means z >= min_z (effect_fit.hpp, step 4), on the
///     criterion's channels that the effects under test act on (EffectFit::acts_on). A joint's
///     friction in the torque residual of a six-joint arm is judged on that joint's torque: on every
///     joint it is diluted by the others' residuals, and where a joint whose torque sensor is quiet
///     carries a large error of its own (weights 1 / sigma^2), every other joint's friction explained
///     under 1% of a real arm's residual while removing most of its own joint's. Where an effect acts
///     on every channel (a force under the one-step and simulation criteria, through the inverse
///     inertia) the share is the fit's own explained.
///
/// Test 3 is on the held-out rows, tests 1 and 2 on the training rows; together they guard against
/// an effect that soaks up the training residual along a direction that happens to help on the
/// held-out rows (a heavy armature on a light joint: the held-out error falls because every torque
/// error is divided by a larger inertia, yet the interval holds 0).

#include <string>
#include <vector>

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"

namespace gpilqg::diagnosis {

/// A parameter that moved further than this many times its scale on the data is not identifiable.
inline constexpr double kRunawayFactor = 100.0;

/// sqrt(machine epsilon): a parameter whose change by its typical size moves the predictions by less
/// than this share of the model's own motion has a regressor of rounding (central differences of
/// quantities that do not depend on it are ~eps relative), not of data.
inline constexpr double kRoundingLevel = 1.4901161193847656e-08;

/// The thresholds of test 3.
struct EffectTestThresholds {
  double min_explained = 0.1;
  double min_z = 3.0;
};

/// The outcome of the test, with one sentence saying why (empty when accepted).
struct EffectTestResult {
  bool accepted = false;
  std::string reason;
};

/// True when v's 95% interval contains v.null_value in every parameter (test 2 fails).
bool interval_contains_null(const EffectValues& v);

/// Tests 1-3 on `fit` (a single effect, or the lead of a joint fit with its members in fit.refitted).
/// Test 2 skips the members named in `already_in_model`: effects the model had before the search are
/// refitted with the new ones, not tested. Test 3 is on the channels of the members in neither
/// `already_in_model` nor `accepted_before` (judged_share): a search step is judged on what it adds.
EffectTestResult test_effect(const EffectFit& fit, const EffectTestThresholds& thresholds,
                             const std::vector<std::string>& already_in_model = {},
                             const std::vector<std::string>& accepted_before = {});

/// The share test 3 judges: heldout_share on the union of the acts_on of the members of `fit` not
/// named in `known` (all channels when that union is empty), and "<what>" for share_text: "the
/// held-out residual" on every channel, else "the held-out residual on the 2 of 6 channels it acts on".
struct JudgedShare {
  HeldoutShare share;
  std::string what;
  std::vector<int> channels;  ///< the channels judged, ascending; empty: every channel
};
JudgedShare judged_share(const EffectFit& fit, const std::vector<std::string>& known, const std::string& residual);

/// Two fits of one context compared on the same held-out batches: the difference of their explained
/// shares, D_a / B - D_b / B = (D_a - D_b) / B, with the ratio estimator's batch-means variance
/// applied to the batch differences,
///
///   Var ~ K / (K - 1) sum_k (d_a,k - d_b,k - difference b_k)^2 / B^2,
///
/// which is far smaller than either share's own variance when the two fits track the same structure
/// (their batch reductions move together). `comparable` is false when the fits have different
/// batches (not of one context) or fewer than two.
struct HeldoutComparison {
  bool comparable = false;
  double difference = 0.0;     ///< a.explained - b.explained
  double difference_ci = 0.0;  ///< 95% half-width, Student's quantile on K - 1 degrees of freedom (student_t.hpp)
};
HeldoutComparison compare_heldout(const EffectFit& a, const EffectFit& b);

/// "removes 12.3% +- 4.1% of <what> (z = 5.2)", or, when the share is not positive, "removes nothing
/// of <what> (it adds 0.04%, z = -1.2)": never a "-0.0%".
std::string share_text(double explained, double explained_ci, double z, const std::string& what);

}  // namespace gpilqg::diagnosis
