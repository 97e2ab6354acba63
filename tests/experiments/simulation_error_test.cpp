// The simulation-error criterion of the diagnosis (simulation_error.hpp): windows restarted from
// measured states, and the acceptance case it exists for: a MuJoCo pendulum with a damping ratio of
// 0.005, whose damping is below the noise of one step but shows over a few periods. The one-step
// criterion misses it; the simulation criterion over windows of 200 samples (2 s, two periods) finds
// joint_viscous_damping:hinge within 15%. The pendulum is passive: a model without actuators, data
// without control columns, the free-swing decay test of system identification.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "diagnosis_support.hpp"
#include "free_decay_pendulum.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/diagnose_request.hpp"
#include "gpilqg/experiments/diagnosis/simulation_error.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using namespace diagnosis;

using test::free_decay;
using test::write_pendulum;
constexpr double kDamping = test::kPendulumDamping;

struct Pendulum {
  fs::path model;  ///< the simulator: the same pendulum without damping
  MeasurementSet data;
};

const Pendulum& pendulum() {
  static const Pendulum p = [] {
    const fs::path dir = test::temporary_dir("simulation_error");
    write_pendulum(dir / "damped.xml", kDamping);
    write_pendulum(dir / "pendulum.xml", 0.0);
    Pendulum p{dir / "pendulum.xml", free_decay(dir / "damped.xml", 10, 7)};
    write_measurements_csv(dir / "free_decay.csv", p.data);  // for `gpilqg diagnose` by hand (docs/diagnosis.md)
    return p;
  }();
  return p;
}

DiagnosisOptions options(FitCriterion criterion, int window) {
  DiagnosisOptions o;
  o.model.system = pendulum().model.string();
  o.gp.points = 60;
  o.gp.restarts = 0;
  o.gp.threads = 1;
  o.horizons = {1};
  o.criterion = criterion;
  o.window = window;
  return o;
}

/// The fit of joint_viscous_damping:hinge in the ranking (the best of its group or an alias).
const EffectFit* damping_fit(const DiagnosisReport& r) {
  for (const RankedEffect& g : r.ranking) {
    if (g.fit.effect == "joint_viscous_damping:hinge") return &g.fit;
    for (const EffectFit& a : g.aliases)
      if (a.effect == "joint_viscous_damping:hinge") return &a;
  }
  return nullptr;
}

TEST(SimulationError, OneStepMissesTheLightDampingAndTheSimulationCriterionFindsIt) {
  const DiagnosisReport one_step = diagnose(pendulum().data, options(FitCriterion::OneStep, 1));
  const EffectFit* missed = damping_fit(one_step);
  ASSERT_NE(missed, nullptr);
  EXPECT_NE(one_step.verdict.status, "explained") << one_step.verdict.reason;
  EXPECT_TRUE(missed->explained < 0.1 || missed->z_score < 3.0) << missed->explained << " z " << missed->z_score;
  std::printf("one-step: verdict %s; damping b = %.5f [%.5f, %.5f], explained %.4f, z %.2f\n  %s\n",
              one_step.verdict.status.c_str(), missed->estimate(0), missed->ci_low(0), missed->ci_high(0),
              missed->explained, missed->z_score, one_step.verdict.reason.c_str());

  const DiagnosisReport simulation = diagnose(pendulum().data, options(FitCriterion::Simulation, 200));
  ASSERT_EQ(simulation.verdict.status, "explained") << simulation.verdict.reason;
  const EffectFit* found = damping_fit(simulation);
  ASSERT_NE(found, nullptr);
  const bool in_verdict_group = simulation.verdict.effect->effect == "joint_viscous_damping:hinge" ||
                                std::count(simulation.verdict.aliases.begin(), simulation.verdict.aliases.end(),
                                           "joint_viscous_damping:hinge") > 0;
  EXPECT_TRUE(in_verdict_group) << simulation.verdict.effect->effect;
  EXPECT_NEAR(found->estimate(0), kDamping, 0.15 * kDamping);
  EXPECT_EQ(simulation.window_restarts, 0);
  std::printf("simulation (window 200): verdict %s (%s); damping b = %.5f [%.5f, %.5f], explained %.4f, z %.2f\n  %s\n",
              simulation.verdict.status.c_str(), simulation.verdict.effect->effect.c_str(), found->estimate(0),
              found->ci_low(0), found->ci_high(0), found->explained, found->z_score, simulation.verdict.reason.c_str());
}

TEST(SimulationError, WindowsRestartFromMeasuredStatesAndWindowOneIsOneStep) {
  const MeasurementSet& set = pendulum().data;
  const Transitions data = make_transitions(set, {1}, set.episodes.front().dt());
  ModelSpec simulator;
  simulator.system = pendulum().model.string();
  const auto model = make_step_model(simulator, Integrator::RK4, 0.01, 1);
  const Matrix one_step = one_step_predictions(*model, data);
  EXPECT_TRUE(simulated_predictions(*model, data, data.u, all_rows(data), 1).isApprox(one_step, 0.0));
  // Window 5: rows 0, 5, 10, ... of every episode start from their measurement, the others continue.
  const Matrix windowed = simulated_predictions(*model, data, data.u, all_rows(data), 5);
  const int second_episode = set.episodes[0].length() - 1;
  for (int r : {0, 5, 10, second_episode, second_episode + 5}) EXPECT_TRUE(windowed.row(r) == one_step.row(r)) << r;
  Vector x = data.x.row(second_episode).transpose(), next(2);
  const auto workspace = model->make_workspace();
  for (int j = 0; j < 5; ++j) {
    model->step(x, data.u.row(second_episode + j).transpose(), next, nullptr, *workspace);
    EXPECT_TRUE(windowed.row(second_episode + j).transpose().isApprox(next, 0.0)) << j;
    x = next;
  }
  EXPECT_FALSE(windowed.row(second_episode + 4).isApprox(one_step.row(second_episode + 4), 1e-9));
  // Over a row subset the windows are those of all rows (fixed by the position in the episode).
  const std::vector<int> heldout = data.rows(true);
  const Matrix subset = simulated_predictions(*model, data, data.u, heldout, 5);
  for (std::size_t k = 0; k < heldout.size(); ++k)
    EXPECT_TRUE(subset.row(static_cast<Eigen::Index>(k)) == windowed.row(heldout[k])) << heldout[k];
  EXPECT_THROW(simulated_predictions(*model, data, data.u, heldout, 0), std::invalid_argument);
}

TEST(SimulationError, TheRequestChecksCriterionAndWindow) {
  DiagnoseRequest r;
  r.system = "cartpole";
  EXPECT_TRUE(diagnosis_options(r).choose_criterion);  // the default: --criterion auto
  EXPECT_EQ(diagnosis_options(r).window, 1);
  const auto message = [&r] {
    try {
      diagnosis_options(r);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  r.window = 50;
  EXPECT_NE(message().find("--window 50: windows belong to --criterion simulation; with --criterion auto the data choose"),
            std::string::npos) << message();
  r.window.reset();
  r.criterion = "one-step";
  EXPECT_FALSE(diagnosis_options(r).choose_criterion);
  EXPECT_EQ(diagnosis_options(r).criterion, FitCriterion::OneStep);
  r.criterion = "simulation";
  EXPECT_NE(message().find("--criterion simulation: expected --window N"), std::string::npos) << message();
  r.window = 50;
  EXPECT_EQ(diagnosis_options(r).criterion, FitCriterion::Simulation);
  EXPECT_EQ(diagnosis_options(r).window, 50);
  r.window = 0;
  EXPECT_NE(message().find("--window 0: expected a whole number of samples from 1"), std::string::npos) << message();
  r.criterion = "one-step";
  r.window = 50;
  EXPECT_NE(message().find("--window 50: windows belong to --criterion simulation"), std::string::npos) << message();
  r.criterion = "inverse-dynamics";
  EXPECT_NE(message().find("--window 50: windows belong to --criterion simulation; the criterion is inverse-dynamics"),
            std::string::npos) << message();
  r.window.reset();
  EXPECT_EQ(diagnosis_options(r).criterion, FitCriterion::InverseDynamics);
  r.criterion = "output";
  EXPECT_NE(message().find("--criterion 'output': expected 'auto', 'one-step', 'simulation', 'inverse-dynamics' or 'inverse-dynamics-iv'"),
            std::string::npos) << message();
  DiagnosisOptions o;
  o.model.system = "cartpole";
  o.window = 5;
  EXPECT_THROW(o.validate(), std::invalid_argument);
}

TEST(SimulationErrorCli, TheCommandLineTakesTheOptionsAndNamesThemInItsErrors) {
  const fs::path dir = test::temporary_dir("simulation_error_cli");
  write_measurements_csv(dir / "decay.csv", pendulum().data);
  const std::string call = "diagnose --system '" + pendulum().model.string() + "' --data '" + (dir / "decay.csv").string() + "'";
  const auto missing = test::run_cli(call + " --criterion simulation");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("--criterion simulation: expected --window N"), std::string::npos) << missing.err;
  const auto one_step = test::run_cli(call + " --window 10");
  EXPECT_EQ(one_step.status, 2);
  EXPECT_NE(one_step.err.find("--window 10: windows belong to --criterion simulation"), std::string::npos) << one_step.err;
  const auto unknown = test::run_cli(call + " --criterion pem --window 10");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("--criterion 'pem': expected 'auto', 'one-step', 'simulation', 'inverse-dynamics' or 'inverse-dynamics-iv'"),
            std::string::npos) << unknown.err;
}

}  // namespace
}  // namespace gpilqg
