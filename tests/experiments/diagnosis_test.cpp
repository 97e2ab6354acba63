// Model diagnosis on data with a hidden effect: the "real world" is the simulator preset plus one effect
// (or none, or one outside the library), simulated with process and observation noise. The diagnosis
// must name the effect (or its alias group) first, recover its parameter within 15% after the refit,
// and show the held-out error and the GP's signal variance fall when it is added; say "consistent"
// when nothing is hidden and "unexplained" when the hidden effect is not in the library. Three seeds
// per case, so that one lucky draw cannot pass.

#include <gtest/gtest.h>

#include <cmath>

#include "diagnosis_support.hpp"
#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/experiments/diagnosis/report.hpp"

namespace gpilqg {
namespace {

using diagnosis::DiagnosisReport;
using diagnosis::EffectFit;

constexpr std::uint64_t kSeeds[] = {11, 22, 33};

struct HiddenCase {
  std::string system;
  std::string effect;
  double value;
  double actuator_noise;
};

std::ostream& operator<<(std::ostream& os, const HiddenCase& c) { return os << c.system << " " << c.effect << "=" << c.value; }

class HiddenEffect : public ::testing::TestWithParam<HiddenCase> {};

/// The fit of `effect` in the first ranked group (the representative or one of its aliases), or null.
const EffectFit* in_first_group(const DiagnosisReport& r, const std::string& effect) {
  if (r.ranking.empty()) return nullptr;
  if (r.ranking[0].fit.effect == effect) return &r.ranking[0].fit;
  for (const EffectFit& a : r.ranking[0].aliases)
    if (a.effect == effect) return &a;
  return nullptr;
}

TEST_P(HiddenEffect, IsRankedFirstFittedAndRemovesTheError) {
  const HiddenCase& c = GetParam();
  ModelSpec world;
  world.system = c.system;
  world = world.with(find_effect(c.system, c.effect), Vector::Constant(1, c.value));
  const int m = c.system == "cartpole" ? 1 : 4;
  for (std::uint64_t seed : kSeeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const MeasurementSet data = test::hidden_effect_data(world.build(test::actuator_noise(m, c.actuator_noise)), seed);
    const DiagnosisReport r = diagnosis::diagnose(data, test::fast_options(c.system));
    EXPECT_FALSE(r.consistent);
    ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
    const EffectFit* fit = in_first_group(r, c.effect);
    ASSERT_NE(fit, nullptr) << "first: " << r.ranking[0].fit.effect << "; " << r.verdict.reason;
    // The parameter after the nonlinear refit, within 15% of the truth, inside a finite interval.
    EXPECT_NEAR(fit->estimate(0), c.value, 0.15 * std::abs(c.value)) << c.effect;
    EXPECT_LT(fit->ci_low(0), fit->ci_high(0));
    EXPECT_TRUE(std::isfinite(fit->ci_low(0)) && std::isfinite(fit->ci_high(0)));
    // Held-out error falls, on the worst state and in the four-model comparison; the GP has less to learn.
    const int worst = diagnosis::worst_state(r);
    EXPECT_LT(fit->heldout_rmse_after(worst), 0.8 * fit->heldout_rmse_before(worst));
    ASSERT_EQ(r.comparison.size(), 4u);
    EXPECT_LT(r.comparison[1].heldout_rmse(worst), 0.8 * r.comparison[0].heldout_rmse(worst));  // sim+effect < sim
    EXPECT_LT(r.comparison[3].signal_variance(worst), 0.5 * r.comparison[2].signal_variance(worst));
    EXPECT_GT(fit->explained, 0.3);
  }
}

INSTANTIATE_TEST_SUITE_P(Library, HiddenEffect,
                         ::testing::Values(HiddenCase{"cartpole", "cart_coulomb_friction", 1.0, 0.02},
                                           HiddenCase{"cartpole", "cart_viscous_friction", 0.8, 0.02},
                                           HiddenCase{"cartpole", "actuator_gain", 0.8, 0.02},
                                           HiddenCase{"cartpole", "param:pole_length", 1.3, 0.02},
                                           HiddenCase{"quadrotor", "param:mass", 0.7, 0.002}),
                         [](const auto& info) {
                           std::string name = info.param.system + "_" + info.param.effect;
                           for (char& ch : name)
                             if (ch == ':') ch = '_';
                           return name;
                         });

TEST(Diagnosis, NothingHiddenIsConsistentAndProposesNothing) {
  ModelSpec world;
  for (std::uint64_t seed : kSeeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const MeasurementSet data = test::hidden_effect_data(world.build(test::actuator_noise(1, 0.02)), seed);
    const DiagnosisReport r = diagnosis::diagnose(data, test::fast_options("cartpole"));
    EXPECT_TRUE(r.consistent);
    EXPECT_EQ(r.verdict.status, "consistent");
    EXPECT_FALSE(r.verdict.effect.has_value());
    EXPECT_TRUE(r.comparison.empty());
    for (const auto& s : r.states) EXPECT_LE(s.heldout_rmse, 1.05 * s.noise_floor) << s.name;
  }
}

/// A test-only effect outside the library: a cubic spring pulling the cart to x = 0, Q_x = -k x^3.
ForceEffectPtr cubic_spring() {
  return std::make_shared<LinearForceEffect>(
      "cubic_spring", EffectParameter{"k", "N/m^3", 1.0}, "Q_x = -k x^3", 2,
      [](const VectorCRef& x, double k, VectorRef Q, Matrix* dQ_dx) {
        Q(0) -= k * x(0) * x(0) * x(0);
        if (dQ_dx != nullptr) (*dQ_dx)(0, 0) -= 3.0 * k * x(0) * x(0);
      });
}

TEST(Diagnosis, AnEffectOutsideTheLibraryIsUnexplained) {
  auto world = std::make_shared<EffectDynamics>(make_system("cartpole"), 1.0,
                                                std::vector<AppliedEffect>{{cubic_spring(), Vector::Constant(1, 8.0)}});
  world->set_noise_model(test::actuator_noise(1, 0.02));
  for (std::uint64_t seed : kSeeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const DiagnosisReport r = diagnosis::diagnose(test::hidden_effect_data(world, seed), test::fast_options("cartpole"));
    EXPECT_FALSE(r.consistent);
    EXPECT_EQ(r.verdict.status, "unexplained") << r.verdict.reason;
    EXPECT_FALSE(r.verdict.effect.has_value());
  }
}

}  // namespace
}  // namespace gpilqg
