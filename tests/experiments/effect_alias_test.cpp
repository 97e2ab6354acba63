// Which effects are aliases (rank_effects, effect_fit.hpp; linearised_fits.hpp): two effects are one
// group when their joint fit removes less than alias_gain (5%) of the held-out residual that either
// leaves alone, or when the system declares them the same physics. On the spring-held carriage of
// models/spring_slide.xml (a linear model, so every force enters the one-step prediction linearly):
//  - the same force under two names is one group: the joint damping and the viscous damping (declared),
//    a world-frame force along the slide and the constant force on it, the carriage's mass and the
//    slide's armature (both only the inertia m + armature of the slide; neither pair is declared, so
//    the rule groups them);
//  - three hidden effects with different regressors (qdot, 1, qdd) are three groups;
//  - a constant force against an actuator gain with a command of mean c0: their regressors have the
//    correlation of the command with a constant, so the joint fit's gain is known in closed form
//    (below), and two commands put it at about 3% and 9%, either side of the threshold.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis_support.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/experiments/diagnosis/linearised_fits.hpp"
#include "spring_slide.hpp"

namespace gpilqg {
namespace {

using namespace diagnosis;

/// Data of the carriage with the hidden effects `truth`, driven by c0 + a multisine of RMS `rms`;
/// velocities measured (one-step criterion), 6 episodes of 3 s.
MeasurementSet carriage_data(const std::vector<std::pair<std::string, double>>& truth, double c0, double rms) {
  const std::string file = test::spring_slide_model();
  ModelSpec world;
  world.system = file;
  for (const auto& [effect, value] : truth) world = world.with(find_effect(file, effect), Vector::Constant(1, value));
  test::SlideRecording s;
  s.command = [c0, rms](int e, int k) { return c0 + test::multisine(e, k, 0.01, rms); };
  s.force_noise = 0.05;
  s.position_noise = 1e-4;
  s.velocity_noise = 2e-3;
  s.seed = 3;
  return test::record_slide(world, s);
}

DiagnosisOptions options() {
  DiagnosisOptions o = test::fast_options(test::spring_slide_model());
  o.horizons = {1};
  return o;
}

/// The index of the ranked group holding `effect` (as its fit or an alias), or -1.
int group_of(const std::vector<RankedEffect>& ranking, const std::string& effect) {
  for (std::size_t g = 0; g < ranking.size(); ++g) {
    if (ranking[g].fit.effect == effect) return static_cast<int>(g);
    for (const EffectFit& a : ranking[g].aliases)
      if (a.effect == effect) return static_cast<int>(g);
  }
  return -1;
}

std::string describe(const std::vector<RankedEffect>& ranking) {
  std::string out;
  for (const RankedEffect& g : ranking) {
    out += "  " + g.fit.effect + " (" + std::to_string(g.fit.explained) + ")";
    for (const EffectFit& a : g.aliases) out += ", alias " + a.effect;
    out += "\n";
  }
  return out;
}

bool declared_same_physics(const std::string& system, const std::string& a, const std::string& b) {
  for (const auto& group : find_system(system)->same_physics)
    if (std::count(group.begin(), group.end(), a) > 0 && std::count(group.begin(), group.end(), b) > 0) return true;
  return false;
}

TEST(EffectAliases, TheSameForceUnderTwoNamesIsOneGroupAndDifferentForcesAreNot) {
  // Hidden: viscous damping (regressor qdot), a constant force (1) and an armature (-qdd): three
  // forces no combination of the others makes. The multisine has mean 0, so the carriage passes
  // through zero velocity and zero acceleration every half period.
  const MeasurementSet data = carriage_data(
      {{"joint_viscous_damping:slide", 0.8}, {"constant_force:slide", 1.0}, {"param:slide.armature", 0.2}}, 0.0, 3.0);
  const DiagnosisOptions o = options();
  const DiagnosisReport r = diagnose(data, o);
  SCOPED_TRACE("ranking:\n" + describe(r.ranking));

  // The same force under two names, by declaration or by the rule alone.
  const std::string file = test::spring_slide_model();
  const std::pair<std::string, std::string> same[] = {{"joint_viscous_damping:slide", "param:slide.damping"},
                                                      {"external_force_x:carriage", "constant_force:slide"},
                                                      {"param:slide.armature", "param:carriage.mass"}};
  EXPECT_TRUE(declared_same_physics(file, same[0].first, same[0].second));
  EXPECT_FALSE(declared_same_physics(file, same[1].first, same[1].second)) << "the rule must group this pair";
  EXPECT_FALSE(declared_same_physics(file, same[2].first, same[2].second)) << "the rule must group this pair";
  for (const auto& [a, b] : same) {
    ASSERT_GE(group_of(r.ranking, a), 0) << a;
    EXPECT_EQ(group_of(r.ranking, a), group_of(r.ranking, b)) << a << " and " << b;
  }
  // The three hidden effects: three groups.
  const int damping = group_of(r.ranking, same[0].first), force = group_of(r.ranking, same[1].first),
            inertia = group_of(r.ranking, same[2].first);
  EXPECT_NE(damping, force);
  EXPECT_NE(damping, inertia);
  EXPECT_NE(force, inertia);

  // The joint fits behind it: a pair of one force's two names gains nothing over either alone (equal
  // columns: the pair's least-squares fit is either one's); a pair of two hidden effects gains what the
  // other explains beyond the first, far above 5%.
  const FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  std::vector<EffectFit> fits;
  for (const auto& [a, b] : same) {
    fits.push_back(fit_effect(find_candidate(r.model, a), context));
    fits.push_back(fit_effect(find_candidate(r.model, b), context));
  }
  const LinearisedFits joint(context, fits, {});
  for (int p = 0; p < 3; ++p) {
    const int a = 2 * p, b = 2 * p + 1;
    EXPECT_GT(joint.gain({a}, {}), 0.1) << joint.names()[a] << " explains a share of its own";
    EXPECT_NEAR(joint.gain({a, b}, {a}), 0.0, 1e-6) << joint.names()[a] << " with " << joint.names()[b];
    EXPECT_NEAR(joint.gain({a, b}, {b}), 0.0, 1e-6) << joint.names()[b] << " with " << joint.names()[a];
    for (int q = p + 1; q < 3; ++q) {
      const int c = 2 * q;
      EXPECT_GT(joint.gain({a, c}, {a}), 0.15) << joint.names()[a] << " with " << joint.names()[c];
      EXPECT_GT(joint.gain({a, c}, {c}), 0.15) << joint.names()[c] << " with " << joint.names()[a];
    }
  }
}

// A constant force F (hidden) against an actuator gain k (not hidden), with the command
// u_t = c0 + m_t (m a multisine of RMS s). The model is linear in both: one step under the force
// k u_t + F is phi = A x_t + b (k u_t + F) (a linear system with a held force), so the weighted
// regressor of F is one vector c on every row and that of k is u_t c. Fitted on the training rows T,
// the gain alone takes theta_k u_t = beta F u_t with beta = sum_T u / sum_T u^2 and leaves
// F^2 |c|^2 (1 - beta u_t)^2 of the force's own share on each held-out row; F alone leaves the noise;
// the pair leaves what F alone leaves. With E_F the held-out share F explains alone and
// D = mean_H (1 - beta u_t)^2 (-> 1 - rho^2, rho^2 = c0^2 / (c0^2 + s^2) the squared correlation of
// the two regressors), the pair removes
//
//   gain(F k over k) = E_F D / (1 - E_F + E_F D)
//
// of what the gain leaves alone, and nothing of what F leaves: aliases exactly when that gain is below
// 5%. With E_F = 0.61 (F = 0.5 N against these noise levels) and c0 = 5 N, s = 0.7 N puts it near 3%
// and s = 1.2 N near 9%.
struct NearAlias {
  double rms;
  bool aliases;
};

std::ostream& operator<<(std::ostream& os, const NearAlias& c) {
  return os << "s = " << c.rms << " N, " << (c.aliases ? "aliases" : "not aliases");
}

class EffectAliasThreshold : public ::testing::TestWithParam<NearAlias> {};

TEST_P(EffectAliasThreshold, APairIsOneGroupExactlyWhenItsJointFitGainsLessThanFivePercent) {
  const NearAlias& c = GetParam();
  const double c0 = 5.0;
  const MeasurementSet data = carriage_data({{"constant_force:slide", 0.5}}, c0, c.rms);
  const DiagnosisOptions o = options();
  const DiagnosisReport r = diagnose(data, o);
  SCOPED_TRACE("ranking:\n" + describe(r.ranking));

  const FitContext context{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  const std::vector<EffectFit> fits{fit_effect(find_candidate(r.model, "constant_force:slide"), context),
                                    fit_effect(find_candidate(r.model, "actuator_gain:drive"), context)};
  const LinearisedFits joint(context, fits, {});
  const double explained_force = joint.gain({0}, {});
  double su = 0.0, suu = 0.0;
  for (int row : r.data.rows(false)) {
    su += r.data.u(row, 0);
    suu += r.data.u(row, 0) * r.data.u(row, 0);
  }
  const double beta = su / suu;
  double D = 0.0;
  const std::vector<int> heldout = r.data.rows(true);
  for (int row : heldout) D += std::pow(1.0 - beta * r.data.u(row, 0), 2);
  D /= static_cast<double>(heldout.size());
  const double closed_form = explained_force * D / (1.0 - explained_force + explained_force * D);
  const double design_D = c.rms * c.rms / (c0 * c0 + c.rms * c.rms);
  std::printf("s = %.2f N: F explains %.4f; D = %.4f (design 1 - rho^2 = %.4f); gain of the pair over the gain alone "
              "%.4f (closed form %.4f), over F alone %.5f\n",
              c.rms, explained_force, D, design_D, joint.gain({0, 1}, {1}), closed_form, joint.gain({0, 1}, {0}));

  // The case sits where it was built to, clear of the threshold, and the joint fit agrees with the
  // closed form (the neglected terms are products of the noise with the fits' errors).
  EXPECT_NEAR(D, design_D, 0.5 * design_D);
  if (c.aliases) EXPECT_LT(closed_form, 0.04);
  else EXPECT_GT(closed_form, 0.065);
  EXPECT_NEAR(joint.gain({0, 1}, {1}), closed_form, 0.01);
  EXPECT_NEAR(joint.gain({0, 1}, {0}), 0.0, 0.005);
  EXPECT_GT(joint.gain({1}, {}), 0.05) << "the gain explains a share of its own (an effect that explains nothing is "
                                          "nobody's alias)";

  // The ranking groups them exactly then: the force first (under either of its names), the gain and the
  // gear (the same physics as the gain, declared) in its group or in a group of their own.
  ASSERT_FALSE(r.ranking.empty());
  const int force = group_of(r.ranking, "constant_force:slide");
  EXPECT_EQ(force, 0);
  EXPECT_EQ(group_of(r.ranking, "external_force_x:carriage"), force);
  const int gain = group_of(r.ranking, "actuator_gain:drive");
  ASSERT_GE(gain, 0);
  EXPECT_EQ(group_of(r.ranking, "param:drive.gear"), gain);
  EXPECT_EQ(gain == force, c.aliases);

  // The threshold is the option's: at 15% the 9% pair is one group too.
  // (The other candidates are left out of this ranking, so that it refits only the four names.)
  if (!c.aliases) {
    FitContext four = context;
    for (const LibraryEffect& e : candidate_effects(r.model))
      if (e.name != "constant_force:slide" && e.name != "external_force_x:carriage" && e.name != "actuator_gain:drive" &&
          e.name != "param:drive.gear")
        four.excluded.push_back(e.name);
    const std::vector<RankedEffect> wide = rank_effects(four, 0.15);
    ASSERT_EQ(wide.size(), 1u) << describe(wide);
    EXPECT_EQ(group_of(wide, "actuator_gain:drive"), group_of(wide, "constant_force:slide")) << describe(wide);
  }
}

INSTANTIATE_TEST_SUITE_P(NearAliases, EffectAliasThreshold,
                         ::testing::Values(NearAlias{0.7, true}, NearAlias{1.2, false}),
                         [](const auto& info) { return info.param.aliases ? "JointGain3Percent" : "JointGain9Percent"; });

}  // namespace
}  // namespace gpilqg
