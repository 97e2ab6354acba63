// The statistics that decide whether an effect is a finding (effect_test.hpp), each on a case built
// to trip it: an interval that holds the value without the effect despite a large z score, a fit that
// runs away along a direction the data barely see, a set with a member that is not needed, a negative
// share printed as a number, the screening of the subset search against a refit on each fold, and a
// single effect that explains much of a residual of two effects (partly explained), and a joint's
// friction judged on the residual of the joint it acts on.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "test_support.hpp"
#include "diagnosis_support.hpp"
#include "free_decay_pendulum.hpp"
#include "gpilqg/experiments/diagnosis/effect_selection.hpp"
#include "gpilqg/experiments/diagnosis/effect_test.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "gpilqg/experiments/diagnosis/student_t.hpp"
#include "gpilqg/experiments/diagnosis/velocity_scales.hpp"

namespace gpilqg {
namespace {

// The small-sample quantiles of the jackknife intervals (student_t.hpp) against a printed table of
// Student's t_{0.975} (Abramowitz & Stegun, table 26.10).
TEST(BatchStatistics, StudentsQuantilesMatchTheTable) {
  using namespace diagnosis;
  const std::map<int, double> t975 = {{1, 12.706}, {2, 4.303}, {3, 3.182}, {6, 2.447}, {10, 2.228}, {30, 2.042}, {120, 1.980}};
  for (const auto& [dof, value] : t975) {
    EXPECT_NEAR(student_t_quantile(0.975, dof), value, 5e-4) << dof;
    EXPECT_NEAR(batch_half_width(2.0, dof + 1), 2.0 * value, 1e-3) << dof;
  }
  EXPECT_THROW(batch_half_width(1.0, 1), std::invalid_argument);
  EXPECT_NEAR(student_t_quantile(0.995, 3), 5.841, 5e-4);
  // t_{0.995, 3} = 5.841 and t_{0.999, 3} = 10.215 have the tails of z = 2.5758 and 3.0902.
  EXPECT_NEAR(normal_equivalent(5.841, 4), 2.5758, 1e-3);
  EXPECT_NEAR(normal_equivalent(10.215, 4), 3.0902, 1e-3);
  EXPECT_NEAR(normal_equivalent(-10.215, 4), -3.0902, 1e-3);
  EXPECT_NEAR(normal_equivalent(3.0, 100000), 3.0, 1e-3);
  EXPECT_EQ(normal_equivalent(1e300, 3), 37.0);
  EXPECT_THROW(student_t_quantile(1.0, 3), std::invalid_argument);
}

using diagnosis::compare_heldout;
using diagnosis::EffectFit;
using diagnosis::EffectTestThresholds;
using diagnosis::HeldoutComparison;
using diagnosis::EffectValues;
using diagnosis::test_effect;

/// The fit of the ranked entry named `effect` (not an alias), or null.
const EffectFit* ranked_fit(const diagnosis::DiagnosisReport& r, const std::string& effect) {
  for (const diagnosis::RankedEffect& g : r.ranking)
    if (g.fit.effect == effect) return &g.fit;
  return nullptr;
}

/// A fit of one parameter that passes every test: 50% explained, z = 10, interval [0.9, 1.1] away from 0.
EffectFit passing_fit(const std::string& name = "cart_coulomb_friction") {
  EffectFit f;
  f.effect = name;
  f.parameters = {{"mu", "N", 1.0, 0.0}};
  f.initial = f.null_value = Vector::Zero(1);
  f.estimate = Vector::Constant(1, 1.0);
  f.ci_low = Vector::Constant(1, 0.9);
  f.ci_high = Vector::Constant(1, 1.1);
  f.scale = Vector::Constant(1, 5.0);
  f.explained = 0.5;
  f.explained_ci = 0.1;
  f.z_score = 10.0;
  return f;
}

TEST(EffectTest, APassingFitIsAccepted) {
  EXPECT_TRUE(test_effect(passing_fit(), {}).accepted) << test_effect(passing_fit(), {}).reason;
}

// The wrist armature of a torque-sensing arm: explained with a large z, yet its interval holds 0.
TEST(EffectTest, AnIntervalHoldingTheValueWithoutTheEffectIsNotAFindingWhateverItsZ) {
  EffectFit f = passing_fit("param:joint7.armature");
  f.parameters = {{"joint7.armature", "kg m^2", 0.01, 0.0}};
  f.estimate = Vector::Constant(1, 0.16);
  f.ci_low = Vector::Constant(1, -0.11);
  f.ci_high = Vector::Constant(1, 0.44);
  f.z_score = 11.4;
  const auto result = test_effect(f, {});
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.reason.find("contains its value without it"), std::string::npos) << result.reason;
  // The null is the value in the model, not 0: a recalibrated mass of 1.0 [0.8, 1.2] in a model of 1.1.
  EffectFit mass = passing_fit("param:pole_mass");
  mass.null_value = Vector::Constant(1, 1.1);
  mass.ci_low = Vector::Constant(1, 0.8);
  mass.ci_high = Vector::Constant(1, 1.2);
  EXPECT_FALSE(test_effect(mass, {}).accepted);
  mass.null_value = Vector::Constant(1, 1.3);
  EXPECT_TRUE(test_effect(mass, {}).accepted);
}

TEST(EffectTest, AFitThatIsNotIdentifiableIsNotAFinding) {
  EffectFit f = passing_fit();
  f.identifiable = false;
  f.not_identifiable = "ran away";
  const auto result = test_effect(f, {});
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.reason.find("not identifiable"), std::string::npos) << result.reason;
  EXPECT_EQ(result.reason.find("the set of"), std::string::npos) << result.reason;
}

// A joint fit is identifiable as a whole or not at all, and the parameter at fault need not be the
// lead's: the reason names the whole set, beside the fit's own text that names the parameter.
TEST(EffectTest, ASetThatIsNotIdentifiableIsNamedAsTheSet) {
  EffectFit set = passing_fit("param:slide.damping");
  set.refitted.push_back({"external_force_y:carriage", {{"F", "N", 1.0}}, Vector::Zero(1), Vector::Zero(1),
                          Vector::Zero(1), Vector::Zero(1), 0.0, Vector::Zero(1)});
  set.identifiable = false;
  set.not_identifiable = "the covariance of F = 0 N is not finite: the data do not see it there";
  const auto result = test_effect(set, {});
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.reason.find("the set of 'param:slide.damping', 'external_force_y:carriage' is not identifiable on "
                               "these data: the covariance of F"),
            std::string::npos)
      << result.reason;
}

TEST(EffectTest, EveryNewMemberOfASetMustExcludeItsValueWithoutIt) {
  EffectFit set = passing_fit();
  EffectValues member{"external_force_x", {{"F", "N", 1.0}}, Vector::Zero(1), Vector::Constant(1, 0.1),
                      Vector::Constant(1, -0.2), Vector::Constant(1, 0.4), 0.0, Vector::Zero(1)};
  set.refitted.push_back(member);
  EXPECT_FALSE(test_effect(set, {}).accepted);
  // A member the model had before the search is refitted, not tested.
  EXPECT_TRUE(test_effect(set, {}, {"external_force_x"}).accepted);
}

TEST(EffectTest, TheSharesAreThresholdsOnTheHeldOutRows) {
  EffectFit f = passing_fit();
  f.explained = 0.08;
  EXPECT_FALSE(test_effect(f, EffectTestThresholds{0.1, 3.0}).accepted);
  EXPECT_TRUE(test_effect(f, EffectTestThresholds{0.05, 3.0}).accepted);
  f.z_score = 2.9;
  EXPECT_FALSE(test_effect(f, EffectTestThresholds{0.05, 3.0}).accepted);
}

TEST(EffectTest, ANegativeShareIsNeverPrintedAsMinusZero) {
  const std::string text = diagnosis::share_text(-0.0004, 0.001, -5.5, "the held-out residual left");
  EXPECT_EQ(text.find("-0.0%"), std::string::npos) << text;
  EXPECT_NE(text.find("removes nothing"), std::string::npos) << text;
  EXPECT_NE(text.find("adds"), std::string::npos) << text;
  EXPECT_NE(diagnosis::share_text(0.123, 0.04, 5.2, "x").find("12.3%"), std::string::npos);
}

// A carriage whose motor delivers 0.5% of the force the model assumes barely accelerates: an armature
// of about 200 times the carriage's mass "explains" that (a = u / (m + armature)), as a heavy armature
// explained a torque-controlled wrist. Its value lies 200 times beyond its scale on the data (the
// carriage's own 2 kg), so it is reported as not identifiable and ranked last; the weak motor is the verdict.
TEST(EffectTest, AnArmatureThatRunsAwayIsNotIdentifiable) {
  const std::string drive = (test::source_dir() / "tests" / "experiments" / "models" / "ball_drive.xml").string();
  ModelSpec world;
  world.system = drive;
  world = world.with(find_effect(drive, "actuator_gain:drive"), Vector::Constant(1, 0.005));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.01));
  ExcitationSettings settings = default_excitation(*dynamics);
  settings.episodes = 6;
  settings.steps = 120;
  settings.seed = 3;
  const MeasurementSet data = simulate_measurements(dynamics, settings).set;

  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, test::fast_options(drive));
  const EffectFit* armature = ranked_fit(r, "param:slide.armature");
  ASSERT_NE(armature, nullptr) << "the armature is in no alias group and ranked on its own";
  EXPECT_FALSE(armature->identifiable) << armature->estimate(0);
  EXPECT_NE(armature->not_identifiable.find("times its scale on these data"), std::string::npos)
      << armature->not_identifiable;
  EXPECT_GT(armature->estimate(0), diagnosis::kRunawayFactor * 2.0);  // beyond 100 carriage masses
  EXPECT_NEAR(armature->scale(0), 2.0, 1.0);                          // the carriage's 2 kg
  // The carriage's mass, which the forces weigh, has a scale of its own 2 kg: the data can weigh it
  // (here it runs away instead, 200 times heavier, as the alias of the weak motor).
  const EffectFit* mass = nullptr;
  for (const diagnosis::RankedEffect& g : r.ranking) {
    if (g.fit.effect == "param:carriage.mass") mass = &g.fit;
    for (const EffectFit& a : g.aliases)
      if (a.effect == "param:carriage.mass") mass = &a;
  }
  ASSERT_NE(mass, nullptr);
  EXPECT_EQ(mass->not_identifiable.find("cannot weigh"), std::string::npos) << mass->not_identifiable;
  EXPECT_NEAR(mass->scale(0), 2.0, 1.0);
  // Never ahead of an identifiable fit, and never the verdict.
  bool seen_unidentifiable = false;
  for (const diagnosis::RankedEffect& g : r.ranking) {
    if (!g.fit.identifiable) seen_unidentifiable = true;
    else EXPECT_FALSE(seen_unidentifiable) << g.fit.effect << " ranked after a fit that is not identifiable";
  }
  // The verdict is the weak motor: its gain, or the gear the model file declares the same physics.
  ASSERT_TRUE(r.verdict.effect.has_value()) << r.verdict.reason;
  const std::string& found = r.verdict.effect->effect;
  EXPECT_TRUE(found == "actuator_gain:drive" || found == "param:drive.gear") << r.verdict.reason;
  EXPECT_NEAR(r.verdict.effect->estimate(0), 0.005, 0.002) << found;
}

// The finite-difference probes of a fit stay within the parameter's physical range: an input delay
// fitted to its largest value (50 steps) was probed at 50.005, which the library refuses, and the
// whole diagnosis of a real 6-axis arm stopped there. At a bound the step is one-sided, inside it
// central, and the width is the distance between the two points.
TEST(EffectFit, TheDifferenceProbesStayWithinTheParametersRange) {
  EffectParameter delay{"d", "steps", 1.0, 0.0, 50.0};
  for (const double value : {50.0, 0.0, 20.0, 49.9999}) {
    const Vector theta = Vector::Constant(1, value);
    const diagnosis::DifferenceStep d = diagnosis::difference_step(delay, theta, 0);
    EXPECT_GE(d.minus(0), delay.lower) << value;
    EXPECT_LE(d.plus(0), delay.upper) << value;
    EXPECT_GT(d.width, 0.0) << value;
    EXPECT_DOUBLE_EQ(d.width, d.plus(0) - d.minus(0)) << value;
  }
  const diagnosis::DifferenceStep top = diagnosis::difference_step(delay, Vector::Constant(1, 50.0), 0);
  EXPECT_EQ(top.plus(0), 50.0);
  EXPECT_DOUBLE_EQ(top.minus(0), 50.0 - 1e-4 * 50.0);
  const diagnosis::DifferenceStep inside = diagnosis::difference_step(delay, Vector::Constant(1, 20.0), 0);
  EXPECT_DOUBLE_EQ(inside.plus(0) - 20.0, 20.0 - inside.minus(0));  // central
  // A range of one point (a parameter pinned by its bounds): no probe moves, and the derivative is 0,
  // not 0/0.
  const EffectParameter pinned{"d", "steps", 1.0, 3.0, 3.0};
  const diagnosis::DifferenceStep fixed = diagnosis::difference_step(pinned, Vector::Constant(1, 3.0), 0);
  EXPECT_EQ(fixed.plus(0), 3.0);
  EXPECT_EQ(fixed.minus(0), 3.0);
  EXPECT_EQ(fixed.inverse_width(), 0.0);
}

// A body's mass in a free swing: MuJoCo scales the body's inertia with its mass, so the motion does not
// change at all and only rounding is left in the regressor. Its fit goes anywhere (the fit's own
// interval is some 1e8 kg wide on a 1 kg bob) and would be ranked: a parameter whose typical size moves
// the predictions by less than kRoundingLevel of the model's own motion is not identifiable.
TEST(EffectTest, AMassThatDoesNotChangeThePredictionsIsNotIdentifiable) {
  const std::filesystem::path dir = test::temporary_dir("mass_free_swing");
  test::write_pendulum(dir / "damped.xml", test::kPendulumDamping);
  test::write_pendulum(dir / "pendulum.xml", 0.0);
  const MeasurementSet data = test::free_decay(dir / "damped.xml", 4, 11);
  diagnosis::DiagnosisOptions o = test::fast_options((dir / "pendulum.xml").string());
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, o);
  const EffectFit* mass = ranked_fit(r, "param:bob.mass");
  ASSERT_NE(mass, nullptr);
  EXPECT_FALSE(mass->identifiable) << mass->estimate(0);
  EXPECT_NE(mass->not_identifiable.find("beyond rounding"), std::string::npos) << mass->not_identifiable;
  EXPECT_GT(mass->scale(0), 1.0 / diagnosis::kRoundingLevel) << "the bob's 1 kg";
  if (r.verdict.effect.has_value()) {
    EXPECT_NE(r.verdict.effect->effect, "param:bob.mass");
  }
}

// With a little damping in the model the bob's mass is seen, through the damping's acceleration
// b qdot / (m l^2), which is some 1/400 of gravity's for b = 1e-3 N m s/rad: only a change of some 400
// times the bob's 1 kg moves the predictions as much as the model itself moves them. The regressor is
// data, not rounding; a mass is measured against its own value, and one that the data cannot weigh
// (more than kRunawayFactor times it) is not identifiable.
TEST(EffectTest, AMassTheDataCannotWeighIsNotIdentifiable) {
  const std::filesystem::path dir = test::temporary_dir("mass_light_damping");
  test::write_pendulum(dir / "pendulum.xml", 1e-3);
  const MeasurementSet data = test::free_decay(dir / "pendulum.xml", 4, 11);
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, test::fast_options((dir / "pendulum.xml").string()));
  const EffectFit* mass = ranked_fit(r, "param:bob.mass");
  ASSERT_NE(mass, nullptr);
  EXPECT_FALSE(mass->identifiable) << mass->estimate(0);
  EXPECT_NE(mass->not_identifiable.find("cannot weigh"), std::string::npos) << mass->not_identifiable;
  EXPECT_GT(mass->scale(0), diagnosis::kRunawayFactor * 1.0) << "the bob's 1 kg";
  EXPECT_LT(mass->scale(0) * diagnosis::kRoundingLevel, 1.0) << "seen beyond rounding";
}

// The scale of an effect on the data is what moves the predictions as much as the model does: for a
// force on the cart-pole's cart, the size of the forces the model applies (tens of N), not 1e-3 or 1e6.
TEST(EffectTest, TheScaleOfAForceIsTheModelsOwnForce) {
  ModelSpec world;
  world.system = "cartpole";
  world = world.with(find_effect("cartpole", "external_force_x"), Vector::Constant(1, 2.0));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.02));
  const MeasurementSet data = test::hidden_effect_data(dynamics, 4);
  diagnosis::DiagnosisOptions o = test::fast_options("cartpole");
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, o);
  ASSERT_FALSE(r.ranking.empty());
  const EffectFit& best = r.ranking.front().fit;
  ASSERT_EQ(best.scale.size(), 1);
  EXPECT_GT(best.scale(0), 0.5) << best.effect;
  EXPECT_LT(best.scale(0), 500.0) << best.effect;
  EXPECT_TRUE(best.identifiable);
}

// The screening of the subset search is a cross-validation on the training rows: checked against a
// second computation that refits each effect exactly with one fold held out (fit_effect on the same
// data with that fold's rows marked held out) and adds up what each fit leaves on its fold.
TEST(EffectTest, TheSubsetScreeningIsACrossValidationOnTheTrainingRows) {
  ModelSpec world;
  world.system = "cartpole";
  world = world.with(find_effect("cartpole", "cart_viscous_friction"), Vector::Constant(1, 0.8));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.02));
  const MeasurementSet data = test::hidden_effect_data(dynamics, 2);
  diagnosis::DiagnosisOptions o = test::fast_options("cartpole");
  o.rank = false;
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, o);
  diagnosis::FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  const LibraryEffect& viscous = find_effect("cartpole", "cart_viscous_friction");
  const LibraryEffect& force = find_effect("cartpole", "external_force_x");
  std::vector<EffectFit> singles{diagnosis::fit_effect(viscous, context), diagnosis::fit_effect(force, context)};
  const diagnosis::LinearisedFits fits(context, singles, {});
  ASSERT_EQ(fits.folds(), 5);  // 7 episodes, 2 held out: 5 training episodes, one per fold

  std::vector<int> training_episodes;
  for (int row : r.data.rows(false)) {
    const int e = r.data.episode[static_cast<std::size_t>(row)];
    if (std::find(training_episodes.begin(), training_episodes.end(), e) == training_episodes.end())
      training_episodes.push_back(e);
  }
  const auto refit_on_folds = [&](const LibraryEffect& effect) {
    double total = 0.0;
    for (std::size_t f = 0; f < training_episodes.size(); ++f) {
      diagnosis::Transitions folded = r.data;
      std::vector<int> fold_rows;
      for (int row = 0; row < folded.size(); ++row) {
        const auto k = static_cast<std::size_t>(row);
        if (r.data.heldout[k]) continue;  // the held-out episodes take no part
        folded.heldout[k] = folded.episode[k] == training_episodes[f];
        if (folded.heldout[k]) fold_rows.push_back(row);
      }
      // Rows of the real held-out episodes must be neither trained on nor scored: drop them.
      std::vector<int> keep;
      for (int row = 0; row < folded.size(); ++row)
        if (!r.data.heldout[static_cast<std::size_t>(row)]) keep.push_back(row);
      diagnosis::Transitions only;
      only.x = folded.x(keep, Eigen::all);
      only.u = folded.u(keep, Eigen::all);
      only.x_next = folded.x_next(keep, Eigen::all);
      only.t = folded.t(keep);
      for (int row : keep) {
        only.episode.push_back(folded.episode[static_cast<std::size_t>(row)]);
        only.heldout.push_back(folded.heldout[static_cast<std::size_t>(row)]);
      }
      diagnosis::FitContext c = context;
      c.data = &only;
      c.residual = r.residual(keep, Eigen::all);
      const EffectFit fit = diagnosis::fit_effect(effect, c);
      const double before = diagnosis::weighted_residual_of(r.model, c, only.rows(true)).squaredNorm();
      total += (1.0 - fit.explained) * before;
    }
    return total;
  };
  EXPECT_NEAR(fits.screening_left({0}), refit_on_folds(viscous), 1e-3 * refit_on_folds(viscous));
  EXPECT_NEAR(fits.screening_left({1}), refit_on_folds(force), 1e-3 * refit_on_folds(force));
  // The truth screens better than the proxy.
  EXPECT_LT(fits.screening_left({0}), fits.screening_left({1}));
}

// Two hidden effects, diagnosed one at a time: the best single effect removes most of the residual,
// but what it leaves still has the other's structure, which the GP of its remainder finds.
TEST(EffectTest, OneOfTwoHiddenEffectsIsPartlyExplained) {
  ModelSpec world;
  world.system = "cartpole";
  world = world.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, 1.5));
  world = world.with(find_effect("cartpole", "external_force_x"), Vector::Constant(1, 0.8));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.02));
  const MeasurementSet data = test::hidden_effect_data(dynamics, 5);
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, test::fast_options("cartpole"));
  EXPECT_EQ(r.verdict.status, "partly_explained") << r.verdict.reason;
  EXPECT_GT(r.verdict.remainder, 1.0 / 3.0) << r.verdict.reason;
}

TEST(EffectTest, TwoFitsAreComparedBatchByBatchOnTheSameHeldOutRows) {
  // Closed form: batches b = 1 each; the first fit removes 0.5 of every batch, the second 0.3 or 0.5
  // in turn. Difference 0.1 (= 0.4 / 4), residuals of the batch differences +-0.1, so the variance
  // of the ratio is K / (K - 1) * 0.04 / B^2 = 4/3 * 0.04 / 16 and the half-width t_{0.975, 3} times its root.
  EffectFit a, b;
  a.heldout_batch_before = b.heldout_batch_before = Vector::Ones(4);
  a.heldout_batch_reduction = Vector::Constant(4, 0.5);
  b.heldout_batch_reduction = (Vector(4) << 0.3, 0.5, 0.3, 0.5).finished();
  const HeldoutComparison c = compare_heldout(a, b);
  ASSERT_TRUE(c.comparable);
  EXPECT_NEAR(c.difference, 0.1, 1e-15);
  EXPECT_NEAR(c.difference_ci, 3.182446305284263 * std::sqrt(4.0 / 3.0 * 0.04) / 4.0, 1e-12);  // t_{0.975, 3}
  // The same reductions in every batch: the difference is certain, however much each share varies.
  b.heldout_batch_reduction = a.heldout_batch_reduction.array() - 0.1;
  a.heldout_batch_reduction = (Vector(4) << 0.9, 0.1, 0.8, 0.2).finished();
  b.heldout_batch_reduction = a.heldout_batch_reduction.array() - 0.05;
  EXPECT_NEAR(compare_heldout(a, b).difference_ci, 0.0, 1e-15);
  // Fits of other rows (other batches) are not compared.
  b.heldout_batch_before(0) = 2.0;
  EXPECT_FALSE(compare_heldout(a, b).comparable);
}

// A criterion that leaves equations out (inverse dynamics at a standstill) leaves batches whose every
// residual is zero, before and after, on the channels it judges. They are no batches: appended to the
// eight batches of the closed form above, channel 1's share, half-width (t_{0.975, 7}, K = 8) and z are
// as without them, while on channel 0, which has equations there, they count. compare_heldout skips
// them the same way.
TEST(EffectTest, BatchesWithoutEquationsAreNoBatchesOfTheShareOrTheComparison) {
  EffectFit f = passing_fit("joint_viscous_friction:joint_2");
  constexpr int K = 8, still = 4;
  f.heldout_channel_before.resize(K + still, 2);
  f.heldout_channel_reduction.resize(K + still, 2);
  for (int b = 0; b < K + still; ++b) {
    f.heldout_channel_before.row(b) << 100.0, b < K ? 1.0 : 0.0;
    f.heldout_channel_reduction.row(b) << 0.0, b < K ? (b % 2 == 0 ? 0.6 : 0.5) : 0.0;
  }
  const diagnosis::HeldoutShare own = diagnosis::heldout_share(f, {1});
  EXPECT_NEAR(own.explained, 0.55, 1e-15);
  EXPECT_NEAR(own.explained_ci, 2.3646242510103 * std::sqrt(8.0 / 7.0 * 8.0 * 0.0025) / 8.0, 1e-4);  // t_{0.975, 7}
  const auto [before, reduction] =
      diagnosis::batches_with_equations(f.heldout_channel_before.col(1), f.heldout_channel_reduction.col(1));
  EXPECT_EQ(before.size(), K);
  EXPECT_EQ(reduction.size(), K);
  EXPECT_EQ(diagnosis::batches_with_equations(f.heldout_channel_before.col(0), f.heldout_channel_reduction.col(0)).first.size(),
            K + still);

  EffectFit a, b;
  a.heldout_batch_before = b.heldout_batch_before = (Vector(6) << 1.0, 1.0, 0.0, 1.0, 1.0, 0.0).finished();
  a.heldout_batch_reduction = (Vector(6) << 0.5, 0.5, 0.0, 0.5, 0.5, 0.0).finished();
  b.heldout_batch_reduction = (Vector(6) << 0.3, 0.5, 0.0, 0.3, 0.5, 0.0).finished();
  const HeldoutComparison c = compare_heldout(a, b);
  ASSERT_TRUE(c.comparable);
  EXPECT_NEAR(c.difference, 0.1, 1e-15);
  EXPECT_NEAR(c.difference_ci, 3.182446305284263 * std::sqrt(4.0 / 3.0 * 0.04) / 4.0, 1e-12);  // K = 4, as above
}

// Inverse dynamics on a real arm: a joint whose torque sensor is quiet (weight 1 / sigma^2) carries a
// large error of its own, and a friction on another joint removes most of that joint's torque residual
// but under 1% of the whole. Closed form: two channels, eight batches; channel 0 has 100 per batch and
// nothing removed, channel 1 has 1 per batch with 0.6 and 0.5 removed in turn. On channel 1 the share is
// 0.55, the batch residuals d - R b are +-0.05, so the variance of the ratio is 8/7 * 8 * 0.0025 / 8^2
// and the half-width t_{0.975, 7} times its root. The friction acts on channel 1 only: it is judged
// there and accepted; an effect acting on both channels is judged on the whole and is not.
TEST(EffectTest, AJointsFrictionIsJudgedOnTheResidualOfTheJointItActsOn) {
  EffectFit f = passing_fit("joint_viscous_friction:joint_2");
  constexpr int K = 8;
  f.heldout_channel_before.resize(K, 2);
  f.heldout_channel_reduction.resize(K, 2);
  for (int b = 0; b < K; ++b) {
    f.heldout_channel_before.row(b) << 100.0, 1.0;
    f.heldout_channel_reduction.row(b) << 0.0, b % 2 == 0 ? 0.6 : 0.5;
  }
  const diagnosis::HeldoutShare whole = diagnosis::heldout_share(f, {});
  EXPECT_NEAR(whole.explained, 4.4 / 808.0, 1e-15);
  f.explained = whole.explained;
  f.explained_ci = whole.explained_ci;
  f.z_score = whole.z_score;
  const diagnosis::HeldoutShare own = diagnosis::heldout_share(f, {1});
  EXPECT_NEAR(own.explained, 0.55, 1e-15);
  EXPECT_NEAR(own.explained_ci, 2.3646242510103 * std::sqrt(8.0 / 7.0 * 8.0 * 0.0025) / 8.0, 1e-4);  // t_{0.975, 7}
  EXPECT_GT(own.z_score, 3.0);
  EXPECT_THROW(diagnosis::heldout_share(f, {2}), std::invalid_argument);

  f.acts_on = {1};
  const diagnosis::EffectTestResult judged = test_effect(f, {});
  EXPECT_TRUE(judged.accepted) << judged.reason;
  f.acts_on = {0, 1};
  const diagnosis::EffectTestResult diluted = test_effect(f, {});
  EXPECT_FALSE(diluted.accepted);
  EXPECT_NE(diluted.reason.find("removes 0.5%"), std::string::npos) << diluted.reason;

  // In a set, what it adds: a member the model had, or one accepted before, does not count.
  f.acts_on = {1};
  EffectValues before = diagnosis::own_values(passing_fit("joint_viscous_friction:joint_1"));
  before.acts_on = {0};
  f.refitted = {before};
  EXPECT_FALSE(test_effect(f, {}).accepted);
  EXPECT_TRUE(test_effect(f, {}, {"joint_viscous_friction:joint_1"}).accepted);
  const diagnosis::EffectTestResult step = test_effect(f, {}, {}, {"joint_viscous_friction:joint_1"});
  EXPECT_TRUE(step.accepted) << step.reason;
  const diagnosis::JudgedShare text = diagnosis::judged_share(f, {"joint_viscous_friction:joint_1"}, "the residual");
  EXPECT_EQ(text.what, "the residual on the 1 of 2 channels the new members act on");
}

}  // namespace
}  // namespace gpilqg
