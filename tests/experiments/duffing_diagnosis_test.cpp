// A Duffing oscillator diagnosed as `gpilqg diagnose --auto` does it. The model is the spring-held
// carriage of models/spring_slide.xml (a linear spring of 20 N/m); the "real" carriage has a hardening
// spring on top, Q = -k3 (q - springref)^3 with k3 = 40 N/m^3 (the library's joint_cubic_spring:slide;
// at the largest excursions of these data, 0.65 m, it adds half the linear spring's force). It is
// driven by a random-phase multisine and only its position is measured (1 mm of noise); the velocity
// is the central difference of the positions and the data say so, so the criterion the diagnosis
// chooses (--criterion auto) is the simulation error. The proposal must be the cubic spring alone, near
// the true k3 (the generator's): none of the linear spring, the mass, the damping or the friction, which
// each explain part of the error of a stiffening oscillator.
//
// What is not asserted, and why. The interval is checked by the single-effect test below. On five
// episodes of 3 s (two held-out: 4 batches) each window's start estimated, --auto added a spurious input
// delay on one seed of ten (z = 4.2 on 4 batches before the z score was studentised) and the
// linear spring was a rival; ten episodes of 6 s give the held-out tests 9 batches.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "diagnosis_support.hpp"
#include "gpilqg/experiments/diagnosis/criteria/criterion_context.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"
#include "spring_slide.hpp"

namespace gpilqg {
namespace {

using namespace diagnosis;

constexpr double kCubic = 40.0;  // N/m^3
const std::string kEffect = "joint_cubic_spring:slide";

/// 10 episodes of 6 s at 100 Hz from rest, multisine of RMS 4 N with 0.05 N of force noise: three held-out
/// episodes give 9 batches of whole windows to the held-out tests.
const MeasurementSet& duffing_data() {
  static const MeasurementSet data = [] {
    const std::string file = test::spring_slide_model();
    ModelSpec world;
    world.system = file;
    world = world.with(find_effect(file, kEffect), Vector::Constant(1, kCubic));
    test::SlideRecording s;
    s.episodes = 10;
    s.steps = 600;
    s.command = [](int e, int k) { return test::multisine(e, k, 0.01, 4.0); };
    s.force_noise = 0.05;
    s.position_noise = 1e-3;
    s.estimate_velocity = true;
    s.seed = 11;
    return test::record_slide(world, s);
  }();
  return data;
}

DiagnosisOptions duffing_options() {
  DiagnosisOptions o = test::fast_options(test::spring_slide_model());
  o.choose_criterion = true;  // the command's default, --criterion auto
  o.horizons = {1};
  return o;
}

TEST(DuffingDiagnosis, AutoProposesTheHardeningSpringAloneNearItsTrueStiffness) {
  double excursion = 0.0;
  for (const Episode& e : duffing_data().episodes) excursion = std::max(excursion, e.x.col(0).cwiseAbs().maxCoeff());
  EXPECT_GT(excursion, 0.5) << "the cubic needs excursions to show";

  DiagnosisOptions o = duffing_options();
  o.auto_select = true;
  const DiagnosisReport r = diagnose(duffing_data(), o);
  // The criterion the data chose: estimated velocities, so the simulation error.
  EXPECT_EQ(r.criterion->kind(), FitCriterion::Simulation) << r.criterion_reason;
  EXPECT_GT(r.criterion->window(), 1);
  EXPECT_NE(r.criterion_reason.find("slide_dot was estimated"), std::string::npos) << r.criterion_reason;

  ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
  ASSERT_TRUE(r.verdict.effect.has_value());
  EXPECT_EQ(r.verdict.effects, std::vector<std::string>{kEffect}) << r.verdict.reason;
  EXPECT_EQ(r.verdict.effect->effect, kEffect);
  EXPECT_TRUE(r.verdict.effect->refitted.empty());
  EXPECT_TRUE(r.verdict.aliases.empty());
  const EffectFit& fit = *r.verdict.effect;
  EXPECT_NEAR(fit.estimate(0), kCubic, 0.1 * kCubic);
  EXPECT_TRUE(fit.identifiable) << fit.not_identifiable;
  EXPECT_GT(fit.ci_low(0), 0.0) << "a spring that hardens, significantly";
  // The proposed model is the model file plus this spring and nothing else.
  ASSERT_TRUE(r.selection.has_value());
  EXPECT_EQ(r.selection->steps.size(), 1u) << r.selection->stop_reason;
  EXPECT_EQ(r.model_next.describe().size(), 1u);
  EXPECT_DOUBLE_EQ(r.model_next.current_values(find_candidate(r.model_next, kEffect))(0), fit.estimate(0));
  std::printf("criterion: %s\nk3 = %.4f [%.4f, %.4f] (true %.1f); rivals %zu; %s\n", r.criterion_reason.c_str(),
              fit.estimate(0), fit.ci_low(0), fit.ci_high(0), kCubic, r.verdict.rivals.size(), r.verdict.reason.c_str());
}

// The single-effect verdict (`gpilqg diagnose` without --auto) on the same data names the cubic
// spring with the true k3 in its interval and no rival. Under the simulation criterion a force linear
// in its parameters still needs the full Gauss-Newton iterations (its prediction over a window is not
// linear in k3: the cubic changes the oscillator's frequency); stopped after the two steps that are
// exact for the one-step error, the fit ended at 36.44 [34.12, 38.75], with a training error 1.6 times
// the converged one, and the linear spring and the mass as rivals. Checked against the fit continued
// from the verdict's estimate, which must not move.
TEST(DuffingDiagnosis, TheSingleEffectVerdictHoldsTheTrueStiffnessInItsInterval) {
  const DiagnosisOptions o = duffing_options();
  const DiagnosisReport r = diagnose(duffing_data(), o);
  ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
  ASSERT_TRUE(r.verdict.effect.has_value());
  EXPECT_EQ(r.verdict.effect->effect, kEffect);
  EXPECT_TRUE(r.verdict.aliases.empty());
  EXPECT_TRUE(r.verdict.rivals.empty());
  const EffectFit& fit = *r.verdict.effect;
  EXPECT_LE(fit.ci_low(0), kCubic) << fit.estimate(0);
  EXPECT_GE(fit.ci_high(0), kCubic) << fit.estimate(0);
  // Converged: Gauss-Newton continued from the verdict's estimate stays there.
  const FitContext base{&r.data, r.model, o.integrator, r.dt, o.substeps, r.weights, r.residual};
  const FitContext context = criterion_context(base, r.criterion->kind(), r.criterion->window());
  const EffectFit more = fit_jointly(find_candidate(r.model, kEffect), {}, context, fit.estimate);
  std::printf("verdict k3 = %.4f [%.4f, %.4f], training error %.6g; continued: %.4f [%.4f, %.4f], %.6g\n",
              fit.estimate(0), fit.ci_low(0), fit.ci_high(0), fit.training_objective_after, more.estimate(0),
              more.ci_low(0), more.ci_high(0), more.training_objective_after);
  EXPECT_NEAR(fit.estimate(0), more.estimate(0), 0.1 * (more.ci_high(0) - more.ci_low(0)));
}

}  // namespace
}  // namespace gpilqg
