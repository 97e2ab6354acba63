// `gpilqg plan` and `gpilqg rollout` (docs/real-robot.md): a scripted loop of the two reproduces
// `gpilqg run`'s gp_ilqg policies, the policy file has the contract's layout and --json its content,
// rollouts log in the data format, and bad input is exit 2 naming the file and the field.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "arm_model.hpp"
#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::quote;

/// One cart-pole task and the loop of the run below, as a `gpilqg run` override ...
constexpr const char* kRunConfig = R"(
[noise]
actuator_multiplicative = [0.02]
observation = [0.001, 0.001, 0.001, 0.001]
[loop]
iterations = 3
rollouts = 2
exploration = [2.0]
policy_tolerance = 0.0
evaluation_rollouts = 1
[gp]
exact_points = 40
restarts = 0
max_evaluations = 40
[solver]
max_iterations = 30
tolerance = 1e-6
gradient_tolerance = 1e-4
[pddp]
enabled = false
[[tasks]]
name = "first"
x0 = [0.0, 0.0, 0.3, 0.0]
goal = [0.0, 0.0, 0.0, 0.0]
horizon = 15
Q = [1.0, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
track_line = false
transfer = false
)";


/// The rollout options of the run's world and loop: its noise, exploration and rollouts per round.
constexpr const char* kRolloutOptions =
    " --multiplicative-noise 0.02 --observation-noise 0.001 --exploration 2 --episodes 2";

/// test::kTinyPlan with its first `from` replaced by `to`.
std::string tiny_plan_with(const std::string& from, const std::string& to) {
  std::string text = test::kTinyPlan;
  text.replace(text.find(from), from.size(), to);
  return text;
}

test::CommandResult plan(const fs::path& config, const std::string& arguments) {
  return test::run_cli("plan " + quote(config) + " " + arguments);
}

/// Rounds 0..rounds of plan, each followed by a rollout, in `dir`: p<k>.h5 and d<k>.h5.
void scripted_loop(const fs::path& dir, const fs::path& config, int rounds, int seed) {
  std::string data;
  for (int k = 0; k <= rounds; ++k) {
    const std::string previous = k > 0 ? " --previous " + quote(dir / fmt::format("p{}.h5", k - 1)) : "";
    const auto p = plan(config, fmt::format("--seed {}{}{} --out {}", seed, data, previous, quote(dir / fmt::format("p{}.h5", k))));
    ASSERT_EQ(p.status, 0) << p.err;
    if (k == rounds) break;
    const auto r = test::run_cli(fmt::format("rollout --system cartpole --policy {} --out {} --seed {}{}",
                                             quote(dir / fmt::format("p{}.h5", k)), quote(dir / fmt::format("d{}.h5", k)),
                                             seed, kRolloutOptions));
    ASSERT_EQ(r.status, 0) << r.err;
    data += " --data " + quote(dir / fmt::format("d{}.h5", k));
  }
}

TEST(PlanCli, AScriptedLoopOfPlanAndRolloutGivesRunsGpIlqgPolicies) {
  // One code path: `gpilqg run`'s gp_ilqg and a loop of plan (fit, solve) and rollout (the world, its
  // noise and the exploration) with the same seed draw the same numbers and solve the same problems.
  const fs::path dir = test::temporary_dir("plan_loop");
  const auto run = test::run_cli("run cartpole --config " + quote(test::write_text(dir / "run.toml", kRunConfig)) +
                                 " --seeds 1 --first-seed 7 --out " + quote(dir / "run.h5"));
  ASSERT_EQ(run.status, 0) << run.err;
  scripted_loop(dir, test::write_text(dir / "plan.toml", test::kTinyPlan), 3, 7);
  const Hdf5Reader results(dir / "run.h5");
  for (int k = 0; k <= 3; ++k) {
    SCOPED_TRACE(fmt::format("round {}", k));
    const PolicyFile p = read_policy_file(dir / fmt::format("p{}.h5", k));
    EXPECT_EQ(p.round, k);
    const std::string it = fmt::format("/first/gp_ilqg/iter_{}", k);
    // The run stores seed x n x (T+1), seed x m x T and seed x T x m x n.
    const std::vector<double> x = results.read_array(it + "/x"), u = results.read_array(it + "/u"),
                              K = results.read_array(it + "/K");
    const Matrix run_x = Eigen::Map<const RowMajorMatrix>(x.data(), 4, 16);
    const Matrix run_u = Eigen::Map<const RowMajorMatrix>(u.data(), 1, 15);
    EXPECT_TRUE(test::matrices_near(p.policy.x_bar, run_x, 1e-9, 1e-9));
    EXPECT_TRUE(test::matrices_near(p.policy.u_bar, run_u, 1e-9, 1e-9));
    for (int t = 0; t < 15; ++t)
      EXPECT_TRUE(test::matrices_near(p.policy.K[static_cast<std::size_t>(t)],
                                      Eigen::Map<const RowMajorMatrix>(K.data() + 4 * t, 1, 4), 1e-9, 1e-9));
  }
  // The rounds differ from each other: the comparison above is not of four copies of one policy.
  EXPECT_GT(read_policy_file(dir / "p1.h5").policy.distance(read_policy_file(dir / "p0.h5").policy), 1e-3);
  EXPECT_GT(read_policy_file(dir / "p3.h5").policy.distance(read_policy_file(dir / "p2.h5").policy), 1e-6);
}

TEST(PlanCli, ThePolicyFileHasTheContractsLayoutAndJsonTheSameContent) {
  const fs::path dir = test::temporary_dir("plan_layout");
  const fs::path config = test::write_text(dir / "plan.toml", test::kTinyPlan);
  scripted_loop(dir, config, 1, 3);
  const auto r = plan(config, "--seed 3 --data " + quote(dir / "d0.h5") + " --previous " + quote(dir / "p0.h5") +
                                  " --out " + quote(dir / "p1_json.h5") + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json doc = json::parse(r.out);  // nothing else on stdout

  const Hdf5Reader h5(dir / "p1_json.h5");
  EXPECT_EQ(h5.shape("/policy/x_bar"), (std::vector<std::uint64_t>{16, 4}));
  EXPECT_EQ(h5.shape("/policy/u_bar"), (std::vector<std::uint64_t>{15, 1}));
  EXPECT_EQ(h5.shape("/policy/K"), (std::vector<std::uint64_t>{15, 1, 4}));
  for (const char* attribute : {"dt", "horizon", "system", "state_names", "control_names", "u_min", "u_max",
                                "predicted_cost", "expected_cost", "round", "data_files", "created", "gpilqg_version"})
    EXPECT_TRUE(h5.has_attribute("/policy", attribute)) << attribute;
  EXPECT_EQ(h5.string_attribute("/policy", "system"), "cartpole");
  EXPECT_EQ(h5.string_list_attribute("/policy", "state_names"), (std::vector<std::string>{"x", "x_dot", "theta", "theta_dot"}));
  EXPECT_EQ(h5.number_attribute("/policy", "round"), 1.0);
  EXPECT_EQ(h5.string_list_attribute("/policy", "data_files"), std::vector<std::string>{(dir / "d0.h5").string()});
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(h5.exists(fmt::format("/model/{}/parameters", i))) << i;
  EXPECT_FALSE(Hdf5Reader(dir / "p0.h5").exists("/model")) << "round 0 has no GP";

  // --json: the same numbers (row-major like the datasets) and attributes.
  const json& p = doc["policy"];
  const std::vector<double> x_bar = h5.read_array("/policy/x_bar"), K = h5.read_array("/policy/K");
  for (std::size_t t = 0; t < 16; ++t)
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(p["x_bar"][t][i].get<double>(), x_bar[t * 4 + i]);
  for (std::size_t t = 0; t < 15; ++t) {
    EXPECT_EQ(p["u_bar"][t][0].get<double>(), h5.read_array("/policy/u_bar")[t]);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(p["K"][t][0][i].get<double>(), K[t * 4 + i]);
  }
  EXPECT_EQ(p["dt"].get<double>(), h5.number_attribute("/policy", "dt"));
  EXPECT_EQ(p["expected_cost"].get<double>(), h5.number_attribute("/policy", "expected_cost"));
  EXPECT_EQ(p["u_max"][0].get<double>(), 25.0);
  EXPECT_EQ(p["created"].get<std::string>(), h5.string_attribute("/policy", "created"));
  EXPECT_EQ(doc["model"]["backend"], "exact");
  EXPECT_EQ(doc["model"]["hyperparameters"].size(), 4u);
  // The same problem, data and seed give the same policy with or without --json.
  EXPECT_EQ(read_policy_file(dir / "p1_json.h5").policy.u_bar, read_policy_file(dir / "p1.h5").policy.u_bar);
  // Written atomically: no temporary file is left beside the policies.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST(PlanCli, RolloutLogsTheMeasuredStatesAndAppliedControlsInCsvOrHdf5) {
  const fs::path dir = test::temporary_dir("rollout_log");
  ASSERT_EQ(plan(test::write_text(dir / "plan.toml", test::kTinyPlan), "--out " + quote(dir / "p.h5")).status, 0);
  const std::string common = " --system cartpole --policy " + quote(dir / "p.h5") + " --seed 5" + kRolloutOptions;
  for (const char* out : {"log.csv", "log.h5"}) {
    const auto r = test::run_cli("rollout" + common + " --out " + quote(dir / out));
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const SystemSignature cartpole = system_signature("cartpole");
  const MeasurementSet csv = read_measurements(dir / "log.csv", cartpole);
  const MeasurementSet h5 = read_measurements(dir / "log.h5", cartpole);
  ASSERT_EQ(csv.episodes.size(), 2u);
  ASSERT_EQ(h5.episodes.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) {
    EXPECT_EQ(csv.episodes[e].x, h5.episodes[e].x);  // the CSV's shortest round-trip numbers lose nothing
    EXPECT_EQ(csv.episodes[e].u, h5.episodes[e].u);
    EXPECT_EQ(csv.episodes[e].length(), 16);
    EXPECT_NEAR(csv.episodes[e].dt(), 0.05, 1e-15);
  }
  EXPECT_NE(csv.episodes[0].x, csv.episodes[1].x) << "two episodes drew the same noise";

  // Without noise or exploration the log is the policy run on the world: each logged control is the
  // policy's control at the logged state.
  const auto quiet = test::run_cli("rollout --system cartpole --policy " + quote(dir / "p.h5") + " --out " +
                                   quote(dir / "quiet.csv"));
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  const Episode e = read_measurements(dir / "quiet.csv", cartpole).episodes.at(0);
  const PolicyFile p = read_policy_file(dir / "p.h5");
  EXPECT_EQ(Vector(e.x.row(0).transpose()), Vector(p.policy.x_bar.col(0)));
  Vector u(1);
  for (int t = 0; t < 15; ++t) {
    p.policy.control(t, e.x.row(t).transpose(), u);
    EXPECT_DOUBLE_EQ(e.u(t, 0), u(0)) << t;
  }
}

TEST(PlanCli, ARoundOnAMujocoModelWithItsWorldGivenAsAFile) {
  // The arm of data/: plan on the model, roll out on a heavier arm given as a second file (the same
  // log as the parameter overrides), plan again on that log.
  const fs::path dir = test::temporary_dir("plan_mujoco");
  const fs::path config = test::write_text(dir / "arm_plan.toml", fmt::format(R"([system]
name = {}
dt = 0.05
[noise]
actuator_multiplicative = [0.02, 0.02]
[problem]
horizon = 20
x0 = [0.0, 0.0, 0.0, 0.0]
goal = [1.0471975511965976, 0.7853981633974483, 0.0, 0.0]
Q = [10.0, 10.0, 0.1, 0.1]
R = [0.01, 0.01]
Qf = [100.0, 100.0, 10.0, 10.0]
u_min = [-12.0, -12.0]
u_max = [12.0, 12.0]
[solver]
max_iterations = 60
[gp]
exact_points = 60
restarts = 0
max_evaluations = 40
)", json(test::arm_model().string()).dump()));
  ASSERT_EQ(plan(config, "--out " + quote(dir / "p0.h5")).status, 0);
  const fs::path world = test::changed_arm(dir, 1.5, 0.3);
  const std::string common = " --system " + quote(test::arm_model()) + " --policy " + quote(dir / "p0.h5") +
                             " --episodes 2 --exploration 1 --observation-noise 0.002 --seed 2";
  const auto by_file = test::run_cli("rollout" + common + " --world " + quote(world) + " --out " + quote(dir / "file.h5"));
  ASSERT_EQ(by_file.status, 0) << by_file.err;
  const auto by_param = test::run_cli("rollout" + common + " --param forearm.mass=0.9 --param elbow.damping=0.3 --out " +
                                      quote(dir / "param.h5"));
  ASSERT_EQ(by_param.status, 0) << by_param.err;
  const SystemSignature arm = system_signature(test::arm_model().string());
  const MeasurementSet a = read_measurements(dir / "file.h5", arm), b = read_measurements(dir / "param.h5", arm);
  ASSERT_EQ(a.episodes.size(), 2u);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_TRUE(test::matrices_near(a.episodes[e].x, b.episodes[e].x, 1e-9, 1e-7));

  const auto next = plan(config, "--data " + quote(dir / "file.h5") + " --previous " + quote(dir / "p0.h5") +
                                     " --out " + quote(dir / "p1.h5") + " --json");
  ASSERT_EQ(next.status, 0) << next.err;
  const json doc = json::parse(next.out);
  EXPECT_EQ(doc["policy"]["round"], 1);
  EXPECT_EQ(doc["data_rows"], 40);
  EXPECT_EQ(doc["model"]["backend"], "exact");
}

/// Exit 2 and a message that names `where` (the file, and the field or option).
void expect_bad_input(const test::CommandResult& r, const std::vector<std::string>& where) {
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("error:", 0), 0u) << r.err;
  for (const auto& text : where) EXPECT_NE(r.err.find(text), std::string::npos) << "'" << text << "' not in: " << r.err;
}

// --write-model writes the model the round planned on whatever the verdict: when the diagnosis adopts
// nothing, the config's simulator with the verdict in its comment, in place of a file an earlier round
// left (a scripted loop would otherwise plan its next round on that stale model).
TEST(PlanCli, WriteModelWritesTheModelPlannedOnAlsoWhenNothingIsAdopted) {
  const fs::path dir = test::temporary_dir("plan_write_kept");
  const fs::path config = test::write_text(dir / "plan.toml", test::kTinyPlan);
  ASSERT_EQ(plan(config, "--out " + quote(dir / "p0.h5")).status, 0);
  const auto r = test::run_cli("rollout --system cartpole --policy " + quote(dir / "p0.h5") + " --out " +
                               quote(dir / "d0.h5") + " --seed 3" + kRolloutOptions);
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path written = test::write_text(dir / "w.toml", "# an earlier round's model\n[model]\nsystem = \"cartpole\"\npreset = \"real\"\n");
  const auto p = plan(config, "--data " + quote(dir / "d0.h5") + " --diagnose --write-model " + quote(written) + " --json --out " +
                                  quote(dir / "p1.h5"));
  ASSERT_EQ(p.status, 0) << p.err;
  const auto json = nlohmann::json::parse(p.out);
  ASSERT_FALSE(json["diagnosis"]["adopted"].get<bool>()) << json["diagnosis"].dump();
  EXPECT_EQ(json["diagnosis"]["model_file"], written.string());
  const std::string text = test::read_text(written);
  EXPECT_NE(text.find("# the config's simulator, kept by `gpilqg plan --diagnose` (verdict " +
                      json["diagnosis"]["verdict"].get<std::string>() + ")"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("preset = \"sim\""), std::string::npos) << text;
  EXPECT_EQ(text.find("earlier round"), std::string::npos) << text;
}

TEST(PlanCli, BadInputIsExit2NamingTheFileAndTheField) {
  const fs::path dir = test::temporary_dir("plan_errors");
  const fs::path config = test::write_text(dir / "plan.toml", test::kTinyPlan);
  ASSERT_EQ(plan(config, "--out " + quote(dir / "p0.h5")).status, 0);
  const std::string p0 = quote(dir / "p0.h5");

  expect_bad_input(plan(config, "--data " + quote(dir / "missing.csv") + " --out " + quote(dir / "x.h5")), {"missing.csv"});
  // Data sampled at 0.02 s for a problem at 0.05 s.
  ASSERT_EQ(test::run_cli("simulate --system cartpole --episodes 1 --steps 20 --dt 0.02 --out " + quote(dir / "fast.csv")).status, 0);
  expect_bad_input(plan(config, "--data " + quote(dir / "fast.csv") + " --out " + quote(dir / "x.h5")),
                   {"fast.csv", "episode 0", "0.05"});
  expect_bad_input(plan(test::write_text(dir / "ilqr.toml", tiny_plan_with("max_iterations = 30", "max_iterations = 30\nalgorithm = \"ilqr\"")),
                        "--out " + quote(dir / "x.h5")),
                   {"ilqr.toml:line 22", "solver.algorithm"});
  expect_bad_input(plan(test::write_text(dir / "gp.toml", std::string(test::kTinyPlan) + "points = 3\n"), "--out " + quote(dir / "x.h5")),
                   {"gp.toml:line 28", "gp.points"});
  // Sensor noise of the wrong size, and negative; a start beyond the divergence bound (the loader of
  // `gpilqg solve`, shared).
  expect_bad_input(plan(test::write_text(dir / "sensors.toml", tiny_plan_with("observation = [0.001, ", "observation = [")),
                        "--out " + quote(dir / "x.h5")),
                   {"sensors.toml:line 9", "noise.observation"});
  expect_bad_input(plan(test::write_text(dir / "negative.toml", tiny_plan_with("observation = [0.001", "observation = [-0.001")),
                        "--out " + quote(dir / "x.h5")),
                   {"negative.toml:line 9", "noise.observation", "negative"});
  expect_bad_input(plan(test::write_text(dir / "far.toml", tiny_plan_with("x0 = [0.0", "x0 = [1e300")), "--out " + quote(dir / "x.h5")),
                   {"far.toml:line", "field 'problem.x0': entry 0 is 1e+300; expected |value| <= 1e+12"});
  // A previous round of another horizon.
  expect_bad_input(plan(test::write_text(dir / "short.toml", tiny_plan_with("horizon = 15", "horizon = 12")), "--previous " + p0 + " --out " + quote(dir / "x.h5")),
                   {"p0.h5", "horizon", "15", "12"});
  // A measurement file is no policy file.
  ASSERT_EQ(test::run_cli("simulate --system cartpole --episodes 1 --steps 20 --dt 0.05 --out " + quote(dir / "log.h5")).status, 0);
  expect_bad_input(plan(config, "--previous " + quote(dir / "log.h5") + " --out " + quote(dir / "x.h5")),
                   {"log.h5", "/policy/x_bar"});
  // --diagnose with nothing to diagnose.
  expect_bad_input(plan(config, "--diagnose --out " + quote(dir / "x.h5")), {"diagnose: no measurement files to diagnose"});
  // --write-model over the model file the config names as its simulator, refused before any work.
  const fs::path named_model = test::write_text(dir / "sm.toml", "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n");
  const fs::path named = test::write_text(dir / "named.toml", tiny_plan_with("preset = \"sim\"", "model = \"sm.toml\""));
  expect_bad_input(plan(named, "--diagnose --write-model " + quote(named_model) + " --out " + quote(dir / "x.h5")),
                   {"--write-model", "sm.toml: is the same file as the config's system.model"});
  EXPECT_EQ(test::read_text(named_model), "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n");
  EXPECT_FALSE(fs::exists(dir / "x.h5")) << "a failed plan wrote its output";

  const std::string rollout = "rollout --policy " + p0 + " --out " + quote(dir / "r.csv");
  expect_bad_input(test::run_cli(rollout + " --system quadrotor"), {"--policy", "p0.h5", "quadrotor"});
  expect_bad_input(test::run_cli(rollout + " --system cartpole --observation-noise 0.1,0.1,0.1"),
                   {"--observation-noise", "3 values"});
  expect_bad_input(test::run_cli(rollout + " --system cartpole --exploration -1"), {"--exploration"});
  // A delay in a world model file is named by its file, not by --effect.
  const fs::path delayed = test::write_text(dir / "delayed.toml", "[model]\nsystem = \"cartpole\"\n[effects]\ninput_delay = 1.0\n");
  expect_bad_input(test::run_cli(rollout + " --system cartpole --world-model " + quote(delayed)),
                   {"--world-model", "delayed.toml: an input delay of 1 control periods"});
  expect_bad_input(test::run_cli(rollout + " --system cartpole --param pole_lenght=1"), {"pole_lenght"});
  expect_bad_input(test::run_cli(rollout + " --system " + quote(test::arm_model())), {"--policy", "p0.h5", "shoulder"});
}

}  // namespace
}  // namespace gpilqg
