// The smoothing velocities v0 of the Coulomb effects of a joint fit, fitted inside the set
// (joint_smoothing, velocity_scales.hpp), against the v0 the data were made with. The "real world" is
// the cart-pole with Coulomb friction on the cart (mu = 1.5 N, v0 = 0.03 m/s) and on the pole
// (tau = 0.3 N m, v0 = 0.025 rad/s) and a constant force on the cart (0.8 N), the frictions being
// tanh(qdot / v0) exactly as the library's. Both v0 lie inside the rule's grid (0.002 to 0.2 times the
// RMS velocity, here 0.25 to 0.30 m/s and 0.26 to 0.33 rad/s) and between its points. The rule
// promises the grid point of least training error refined by a parabola in log v0: so within a grid
// step (a factor 2 to 2.5) of the truth, and closer where the refinement works. Each v0 fitted alone
// is biased by the other effects (the constant force, the other friction): the set's must not be,
// and the levels refitted at the set's v0 must hold the truth in their 95% intervals.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <string>

#include "diagnosis_support.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "gpilqg/experiments/diagnosis/velocity_scales.hpp"

namespace gpilqg {
namespace {

using namespace diagnosis;

constexpr double kCartMu = 1.5, kCartV0 = 0.03;   // N, m/s
constexpr double kPoleTau = 0.3, kPoleV0 = 0.025;  // N m, rad/s
constexpr double kForce = 0.8;                     // N

/// The cart-pole world with the two frictions and the force, 8 episodes of 150 samples (default
/// excitation: +-5 N held for 5 samples; observation noise 1e-3; actuator noise 0.02 N).
MeasurementSet friction_data(std::uint64_t seed) {
  ModelSpec world;
  world.system = "cartpole";
  world.smoothing["cart_coulomb_friction"] = kCartV0;
  world.smoothing["pole_coulomb_friction"] = kPoleV0;
  world = world.with(find_candidate(world, "cart_coulomb_friction"), Vector::Constant(1, kCartMu));
  world = world.with(find_candidate(world, "pole_coulomb_friction"), Vector::Constant(1, kPoleTau));
  world = world.with(find_candidate(world, "external_force_x"), Vector::Constant(1, kForce));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.02));
  ExcitationSettings settings = default_excitation(*dynamics);
  settings.episodes = 8;
  settings.steps = 150;
  settings.seed = seed;
  return simulate_measurements(dynamics, settings).set;
}

/// The joint fit of the three effects at the smoothing of `model` (frictions first).
EffectFit fit_set(const ModelSpec& model, const FitContext& context, const EffectFit* start = nullptr) {
  FitContext c = context;
  c.model = model;
  const LibraryEffect cart = find_candidate(model, "cart_coulomb_friction");
  const LibraryEffect pole = find_candidate(model, "pole_coulomb_friction");
  const LibraryEffect force = find_candidate(model, "external_force_x");
  if (start == nullptr) return fit_jointly(cart, {{&pole, Vector::Zero(1)}, {&force, Vector::Zero(1)}}, c);
  return fit_jointly(cart, {{&pole, start->refitted[0].estimate}, {&force, start->refitted[1].estimate}}, c,
                     start->estimate);
}

TEST(JointSmoothing, TheSetsSmoothingVelocitiesAreTheDatasAndItsLevelsHoldTheTruth) {
  for (std::uint64_t seed : {5u, 6u, 7u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    DiagnosisOptions o = test::fast_options("cartpole");
    o.rank = false;
    const DiagnosisReport r = diagnose(friction_data(seed), o);
    // The context of the ranking: the model as given with each Coulomb v0 fitted alone.
    const FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
    const double alone_cart = r.model.smoothing.at("cart_coulomb_friction");
    const double alone_pole = r.model.smoothing.at("pole_coulomb_friction");
    const double rms_cart = training_rms(r.data, 1), rms_pole = training_rms(r.data, 3);
    ASSERT_GT(kCartV0, 0.05 * rms_cart) << "the truth lies inside the grid, between its points";
    ASSERT_LT(kCartV0, 0.2 * rms_cart);
    ASSERT_GT(kPoleV0, 0.05 * rms_pole);
    ASSERT_LT(kPoleV0, 0.2 * rms_pole);

    const EffectFit set = fit_set(r.model, context);
    const std::map<std::string, double> v0 = joint_smoothing(context, set);
    ASSERT_EQ(v0.size(), 2u) << "one v0 per Coulomb effect of the set, none for the force";
    const double cart = v0.at("cart_coulomb_friction"), pole = v0.at("pole_coulomb_friction");

    // Within a factor 1.25 (cart) and 1.5 (the weaker pole friction) of the truth: less than the grid
    // step of 2 around them.
    EXPECT_LT(std::abs(std::log(cart / kCartV0)), std::log(1.25)) << cart;
    EXPECT_LT(std::abs(std::log(pole / kPoleV0)), std::log(1.5)) << pole;
    // The cart's v0 fitted alone, biased by the constant force and the pole's friction, is further off.
    EXPECT_LT(std::abs(std::log(cart / kCartV0)), std::abs(std::log(alone_cart / kCartV0))) << alone_cart;

    // The set refitted at its v0 (as the subset search does): every level holds the truth, and the
    // training error is that of the set at the true v0 within 1% (an exact refit, not the linearised
    // fits joint_smoothing chose with).
    ModelSpec fitted = r.model, truth = r.model;
    fitted.smoothing["cart_coulomb_friction"] = cart;
    fitted.smoothing["pole_coulomb_friction"] = pole;
    truth.smoothing["cart_coulomb_friction"] = kCartV0;
    truth.smoothing["pole_coulomb_friction"] = kPoleV0;
    const EffectFit refit = fit_set(fitted, context, &set);
    const EffectFit at_truth = fit_set(truth, context, &set);
    ASSERT_EQ(refit.refitted.size(), 2u);
    EXPECT_LE(refit.ci_low(0), kCartMu);
    EXPECT_GE(refit.ci_high(0), kCartMu);
    EXPECT_LE(refit.refitted[0].ci_low(0), kPoleTau);
    EXPECT_GE(refit.refitted[0].ci_high(0), kPoleTau);
    EXPECT_NEAR(refit.refitted[1].estimate(0), kForce, 0.05 * kForce);
    EXPECT_LT(refit.training_objective_after, 1.01 * at_truth.training_objective_after);
    std::printf("seed %d: v0 cart %.4f (alone %.4f, true %.3f), pole %.4f (alone %.4f, true %.3f); mu = %.4f [%.4f, %.4f], "
                "tau = %.4f [%.4f, %.4f], F = %.4f; training error %.1f (%.1f at the true v0)\n",
                static_cast<int>(seed), cart, alone_cart, kCartV0, pole, alone_pole, kPoleV0, refit.estimate(0),
                refit.ci_low(0), refit.ci_high(0), refit.refitted[0].estimate(0), refit.refitted[0].ci_low(0),
                refit.refitted[0].ci_high(0), refit.refitted[1].estimate(0), refit.training_objective_after,
                at_truth.training_objective_after);
  }
}

// The v0 of a Coulomb candidate before any set (with_fitted_smoothing, as the ranking and the subset
// search's screening use it) is fitted with a viscous friction of its coordinate beside it. On a cart
// with viscous friction 4 N s/m and Coulomb friction 1.5 N at v0 = 0.006 m/s (4% of the rms speed), a
// second implementation scores every grid point by exact fits (fit_jointly on the training rows): the
// rule's v0 is within a grid step of the truth and at the grid point the exact fits with the viscous
// friction prefer, while the exact fits of the Coulomb friction alone prefer the top of the grid (a
// saturating viscous friction), the width the rule took before the viscous column. The same holds for
// the width fitted again inside a set that has no viscous friction of the coordinate.
TEST(JointSmoothing, ACoulombCandidatesWidthIsFittedBesideItsCoordinatesViscousFriction) {
  constexpr double kViscous = 4.0, kV0 = 0.006;  // N s/m; m/s, 4% of the rms speed
  ModelSpec world;
  world.system = "cartpole";
  world.smoothing["cart_coulomb_friction"] = kV0;
  world = world.with(find_candidate(world, "cart_coulomb_friction"), Vector::Constant(1, kCartMu));
  world = world.with(find_candidate(world, "cart_viscous_friction"), Vector::Constant(1, kViscous));
  const DynamicsPtr dynamics = world.build(test::actuator_noise(1, 0.02));
  ExcitationSettings settings = default_excitation(*dynamics);
  settings.episodes = 8;
  settings.steps = 150;
  settings.seed = 5;
  DiagnosisOptions o = test::fast_options("cartpole");
  o.rank = false;
  const DiagnosisReport r = diagnose(simulate_measurements(dynamics, settings).set, o);
  const FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  const double rms = training_rms(r.data, 1);
  const double rule = r.model.smoothing.at("cart_coulomb_friction");
  int with_viscous = 0, alone = 0;
  double best_with = 0.0, best_alone = 0.0;
  for (int i = 0; i < static_cast<int>(std::size(kSmoothingGrid)); ++i) {
    ModelSpec m = r.model;
    m.smoothing["cart_coulomb_friction"] = kSmoothingGrid[i] * rms;
    FitContext c = context;
    c.model = m;
    const LibraryEffect coulomb = find_candidate(m, "cart_coulomb_friction");
    const LibraryEffect viscous = find_candidate(m, "cart_viscous_friction");
    const double pair = fit_jointly(coulomb, {{&viscous, Vector::Zero(1)}}, c).training_objective_after;
    const double single = fit_jointly(coulomb, {}, c).training_objective_after;
    if (i == 0 || pair < best_with) best_with = pair, with_viscous = i;
    if (i == 0 || single < best_alone) best_alone = single, alone = i;
  }
  std::printf("v0 %.4f m/s (truth %.3f, rms speed %.3f); exact fits prefer %.4f with the viscous friction, %.4f alone\n", rule,
              kV0, rms, kSmoothingGrid[with_viscous] * rms, kSmoothingGrid[alone] * rms);
  ASSERT_LT(kV0, 0.1 * rms) << "the truth lies well inside the grid";
  EXPECT_LT(std::abs(std::log(rule / kV0)), std::log(2.5)) << rule;
  EXPECT_LT(std::abs(std::log(rule / (kSmoothingGrid[with_viscous] * rms))), std::log(2.5)) << rule;
  EXPECT_EQ(alone, static_cast<int>(std::size(kSmoothingGrid)) - 1) << "alone, the switch's width takes the viscous slope";

  // Inside a set that lacks the viscous friction (joint_smoothing of the Coulomb friction fitted
  // alone), the width is still the switch's: the set's fit has the viscous friction beside it too.
  const LibraryEffect coulomb = find_candidate(r.model, "cart_coulomb_friction");
  const double in_set = joint_smoothing(context, fit_jointly(coulomb, {}, context)).at("cart_coulomb_friction");
  std::printf("inside a set without the viscous friction: v0 %.4f m/s\n", in_set);
  EXPECT_LT(std::abs(std::log(in_set / kV0)), std::log(2.5)) << in_set;
  EXPECT_LT(in_set, kSmoothingGrid[alone] * rms / 2.0) << in_set;
}

// joint_smoothing moves one Coulomb member's v0 at a time and replaces only that member's columns of
// the linearised fits (LinearisedFits::relinearise). Every score must be that of the set linearised
// afresh at the new v0 (a second computation: every column and the base residual again).
TEST(JointSmoothing, ReplacingOneMembersColumnsIsTheSetLinearisedAfresh) {
  DiagnosisOptions o = test::fast_options("cartpole");
  o.rank = false;
  const DiagnosisReport r = diagnose(friction_data(5), o);
  const FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  const EffectFit set = fit_set(r.model, context);
  const std::vector<EffectFit> members = member_fits(set);
  ASSERT_EQ(members[0].effect, "cart_coulomb_friction");
  LinearisedFits kept(context, members, {}, 1, true);
  FitContext moved = context;
  for (const double factor : {0.4, 3.0}) {
    moved.model.smoothing["cart_coulomb_friction"] = factor * r.model.smoothing.at("cart_coulomb_friction");
    kept.relinearise(0, moved);
    const LinearisedFits fresh(moved, members, {});
    for (const std::vector<int>& subset : {std::vector<int>{0}, {0, 2}, {0, 1, 2}, {1, 2}}) {
      EXPECT_NEAR(kept.training_left(subset), fresh.training_left(subset), 1e-9 * fresh.training_left({}));
      EXPECT_NEAR(kept.heldout_left(subset), fresh.heldout_left(subset), 1e-9 * fresh.heldout_base());
      const std::vector<double> a = kept.screening_folds(subset), b = fresh.screening_folds(subset);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t f = 0; f < a.size(); ++f) EXPECT_NEAR(a[f], b[f], 1e-9 * fresh.training_left({}));
    }
    // The move is not a no-op: the cart's own fit differs from that at the first v0.
    EXPECT_NE(kept.training_left({0}), LinearisedFits(context, members, {}).training_left({0}));
  }
}

}  // namespace
}  // namespace gpilqg
