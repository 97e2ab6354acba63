/// The diagnosed model as GP-ILQG's simulator: a model file of `gpilqg diagnose` in a config's
/// [system] and [world], and the diagnosis inside the loop ([diagnosis] after_round). Checked against
/// the truth the world was built with: the rollouts of a world with a longer pole and Coulomb friction
/// on the cart are diagnosed to those two effects at their values, and the plans after the diagnosis
/// are made on the residual GP around that model; the checkpoint and the result file keep it.

#include "gpilqg/experiments/loop_diagnosis.hpp"

#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/algorithm_runs.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_checkpoint.hpp"
#include "gpilqg/experiments/run_experiment.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/plan_config.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg/gp/residual_model.hpp"
#include "same_run_results.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

constexpr double kFriction = 3.0;  // [N], the world's Coulomb friction on the cart

/// The world of these tests: the "real" preset (its pole is longer than the simulator's) with Coulomb
/// friction on the cart, as a model file.
std::filesystem::path write_world(const std::filesystem::path& folder) {
  const auto file = folder / "world.toml";
  test::write_text(file, fmt::format("[model]\nsystem = \"cartpole\"\npreset = \"real\"\n[effects]\n"
                                     "cart_coulomb_friction = {{ mu = {}, v0 = 0.05 }}\n",
                                     kFriction));
  return file;
}

/// Expects `text` to hold every one of `parts`.
void expect_holds(const std::string& text, std::initializer_list<std::string> parts) {
  for (const auto& part : parts) EXPECT_NE(text.find(part), std::string::npos) << "'" << part << "' not in: " << text;
}

double parameter(const Dynamics& system, const std::string& name) {
  for (const Parameter& p : system.parameters())
    if (p.name == name) return p.value;
  throw std::runtime_error("no parameter " + name);
}

double real_pole_length() { return parameter(*make_system("cartpole", Preset::RealWorld), "pole_length"); }

TEST(EpisodesOf, SplitsTransitionsWhereARolloutStartsAgainOrTheRoundChanges) {
  TransitionData data;
  data.x.resize(5, 1);
  data.u.resize(5, 1);
  data.x_next.resize(5, 1);
  data.x << 0, 1, 0, 1, 2;  // rollout 0: 0 -> 1 -> 2; rollout 1: 0 -> 1; rollout 2 (round 1): 2 -> 3
  data.x_next << 1, 2, 1, 2, 3;
  data.u << 10, 11, 12, 13, 14;
  data.iteration = {0, 0, 0, 0, 1};
  SystemSignature signature;
  signature.states = {{"x", "m"}};
  signature.controls = {{"u", "N"}};
  const MeasurementSet set = episodes_of(data, signature, 0.1);
  ASSERT_EQ(set.episodes.size(), 3u);
  EXPECT_EQ(set.episodes[0].x.col(0).transpose(), (Vector(3) << 0, 1, 2).finished().transpose());
  EXPECT_EQ(set.episodes[0].u(1, 0), 11.0);
  EXPECT_EQ(set.episodes[1].x.col(0).transpose(), (Vector(3) << 0, 1, 2).finished().transpose());
  EXPECT_EQ(set.episodes[2].x.col(0).transpose(), (Vector(2) << 2, 3).finished().transpose());
  EXPECT_DOUBLE_EQ(set.episodes[0].dt(), 0.1);
}

TEST(LoopDiagnosis, FindsTheLongerPoleAndTheCartFrictionInRolloutsOfTheWorld) {
  const auto folder = test::temporary_dir("loop_diagnosis_world");
  const RunConfig config = parse_run_config(
      "cartpole", fmt::format("[world]\nmodel = \"{}\"\n", write_world(folder).string()), (folder / "c.toml").string());
  ASSERT_EQ(config.world.forces.size(), 1u);
  // Rollouts of the world under a smooth random drive, measured with 1 mm / 1 mrad noise.
  const auto world = make_step_model(config.world.build({}), config.integrator, config.dt, config.substeps);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  MeasurementSet set;
  set.system = system_signature("cartpole");
  constexpr int T = 40;
  for (int episode = 0; episode < 6; ++episode) {
    Episode e;
    e.t = Vector::LinSpaced(T + 1, 0.0, T * config.dt);
    e.x = Matrix::Zero(T + 1, 4);
    e.u = Matrix::Zero(T + 1, 1);
    Vector x = Vector::Zero(4), next(4);
    const double amplitude = 6.0 + 2.0 * episode, phase = normal(rng);
    for (int t = 0; t <= T; ++t) {
      for (int i = 0; i < 4; ++i) e.x(t, i) = x(i) + 1e-3 * normal(rng);
      e.u(t, 0) = amplitude * std::sin(0.35 * t + phase) + 2.0 * normal(rng);
      world->step(x, e.u.row(t).transpose(), next);
      x = next;
    }
    set.episodes.push_back(std::move(e));
  }
  TransitionData data;
  data.append(set, 0);
  const LoopDiagnosis d = diagnose_loop_data(loop_model(config), data, 0, 11);
  ASSERT_EQ(d.verdict, "explained") << d.reason;
  EXPECT_TRUE(d.adopted);
  ASSERT_TRUE(d.model.parameters.count("pole_length"));
  EXPECT_NEAR(d.model.parameters.at("pole_length"), real_pole_length(), 0.05 * real_pole_length());
  ASSERT_EQ(d.model.forces.size(), 1u);
  EXPECT_EQ(d.model.forces.front().first, "cart_coulomb_friction");
  EXPECT_NEAR(d.model.forces.front().second(0), kFriction, 0.1 * kFriction);
  EXPECT_EQ(diagnosed_from(d), 1);
  std::filesystem::remove_all(folder);
}

/// The tiny run of the experiment tests in the world above, diagnosing after round 0 of sixteen rollouts
/// (240 transitions: the held-out test needs about ten batches of ten rows to call a finding).
RunConfig diagnosing_config(const std::filesystem::path& folder) {
  std::string text = test::kTinyRun;
  const std::string loop = "[loop]\niterations = 2\nrollouts = 1\n";
  text.replace(text.find(loop), loop.size(), "[loop]\niterations = 2\nrollouts = 16\nexploration = [8.0]\n");
  text.replace(text.find("[pddp]\n"), 7, "[pddp]\nenabled = false\n");
  text += fmt::format("[world]\nmodel = \"{}\"\n[diagnosis]\nafter_round = 0\n", write_world(folder).string());
  return parse_run_config("cartpole", text, (folder / "run.toml").string());
}

TEST(LoopDiagnosis, PlansAfterTheDiagnosedRoundOnTheDiagnosedModelAndKeepsItInTheResult) {
  const auto folder = test::temporary_dir("loop_diagnosis_run");
  const RunConfig config = diagnosing_config(folder);
  RunOptions options;
  options.seeds = {5};
  const RunResults results = run_experiment(config, options);
  for (std::size_t t = 0; t < 2; ++t) {
    const auto& runs = results.tasks[t].seeds.front();
    const auto gp_ilqg = std::find_if(runs.begin(), runs.end(), [](const AlgorithmRun& r) { return r.name == "gp_ilqg"; });
    ASSERT_NE(gp_ilqg, runs.end());
    ASSERT_TRUE(gp_ilqg->diagnosis.has_value());
    const LoopDiagnosis& d = *gp_ilqg->diagnosis;
    SCOPED_TRACE(diagnosis_summary(d));
    EXPECT_EQ(d.round, t == 0 ? 0 : -1);  // the transfer task starts from the first task's model
    ASSERT_TRUE(d.adopted);
    // Iteration 0 of the first task plans on the simulator; every plan on data after the diagnosis on
    // a GP around the diagnosed model, which holds the world's friction.
    const auto* first = dynamic_cast<const gp::ResidualModel*>(gp_ilqg->iterations[t == 0 ? 1 : 0].plan.model.get());
    ASSERT_NE(first, nullptr);
    ASSERT_EQ(d.model.forces.size(), 1u);
    EXPECT_EQ(d.model.forces.front().first, "cart_coulomb_friction");
    // What the GP wraps steps as the diagnosed model does, and not as the config's simulator: at a
    // moving cart, where the friction the simulator lacks acts.
    const auto diagnosed = make_step_model(d.model.build(config.noise), config.integrator, config.dt, config.substeps);
    const auto bare = make_step_model(config.simulator.build(config.noise), config.integrator, config.dt, config.substeps);
    Vector x(4), u(1), wrapped(4), expected(4), simulators(4);
    x << 0.1, 0.5, 0.3, -0.2;
    u << 2.0;
    first->simulator().step(x, u, wrapped);
    diagnosed->step(x, u, expected);
    bare->step(x, u, simulators);
    EXPECT_EQ(wrapped, expected);
    EXPECT_GT((wrapped - simulators).norm(), 1e-3);
  }
  const auto file = folder / "run.h5";
  write_run_results(file, results);
  const Hdf5Reader h5(file);
  const std::string group = "/" + config.tasks[0].name + "/gp_ilqg";
  EXPECT_EQ(h5.read_vector(group + "/diagnosed_from")(0), 1.0);
  EXPECT_EQ(h5.read_vector(group + "/diagnosis_round")(0), 0.0);
  EXPECT_NE(h5.string_list_attribute(group + "/diagnosed_from", "diagnosis").at(0).find("cart_coulomb_friction"),
            std::string::npos);
  EXPECT_NE(h5.string_list_attribute(group + "/diagnosed_from", "model").at(0).find("[effects]"), std::string::npos);
  EXPECT_FALSE(h5.exists("/" + config.tasks[0].name + "/ilqg_real/diagnosed_from"));

  // Stopped right after the diagnosis and resumed: the same results, the same diagnosed model.
  const auto checkpoint = folder / "run.h5.checkpoint";
  {
    RunCheckpoint first = RunCheckpoint::create(checkpoint, config, options);
    int saves = 0;
    first.set_stop_requested([&saves] { return ++saves == 4; });  // ilqg_real, ilqg_sim, gp_ilqg 0, 1
    RunOptions stopping = options;
    stopping.journal = &first;
    EXPECT_THROW(run_experiment(config, stopping), RunInterrupted);
  }
  RunCheckpoint second = RunCheckpoint::resume(checkpoint, config, options);
  RunOptions resuming = options;
  resuming.journal = &second;
  const RunResults resumed = run_experiment(config, resuming);
  EXPECT_GT(second.restored_count(), 0);
  test::expect_same_results(resumed, results);
  std::filesystem::remove_all(folder);
}

TEST(LoopDiagnosisCli, PlanDiagnosesTheLogsWritesTheModelAndTheNextRoundPlansOnIt) {
  // The loop on a robot: plan, roll out on the world, plan --diagnose (the model file for the next
  // config), roll out, plan with [system] model = the diagnosed model.
  const auto dir = test::temporary_dir("plan_diagnose");
  write_world(dir);
  const std::string plan_text = test::kTinyPlan;
  const auto bare = test::write_text(dir / "plan.toml", plan_text);
  const auto cli = [&](const std::string& arguments) {
    const auto r = test::run_cli(arguments);
    EXPECT_EQ(r.status, 0) << arguments << "\n" << r.err;
    return r;
  };
  const auto rollout = [&](const std::string& policy, const std::string& log) {
    cli(fmt::format("rollout --system cartpole --world-model {} --policy {} --out {} --seed 3 --episodes 16 "
                    "--exploration 8 --observation-noise 0.001",
                    test::quote(dir / "world.toml"), test::quote(dir / policy), test::quote(dir / log)));
  };
  cli(fmt::format("plan {} --out {}", test::quote(bare), test::quote(dir / "p0.h5")));
  rollout("p0.h5", "d0.h5");
  const auto diagnosed = cli(fmt::format("plan {} --data {} --previous {} --diagnose --write-model {} --out {}",
                                         test::quote(bare), test::quote(dir / "d0.h5"), test::quote(dir / "p0.h5"),
                                         test::quote(dir / "F.toml"), test::quote(dir / "p1.h5")));
  expect_holds(diagnosed.out, {"diagnosis: explained after round 0", "cart_coulomb_friction", "wrote it to"});
  const ModelSpec model = diagnosis::read_model_file(dir / "F.toml", "cartpole");
  ASSERT_EQ(model.forces.size(), 1u);
  EXPECT_EQ(model.forces.front().first, "cart_coulomb_friction");
  const PolicyFile p1 = read_policy_file(dir / "p1.h5");
  EXPECT_EQ(p1.simulator_model, diagnosis::model_file_text(model));
  rollout("p1.h5", "d1.h5");

  // The next round on [system] model = F.toml: its GP warm-starts from p1's, fitted around the same
  // simulator; the bare config's cannot.
  std::string with_model = plan_text;
  const std::string preset = "preset = \"sim\"";
  const auto modelled = test::write_text(dir / "modelled.toml", with_model.replace(with_model.find(preset), preset.size(),
                                                                                   "model = \"F.toml\""));
  const std::string data = fmt::format("--data {} --data {} --previous {} --json", test::quote(dir / "d0.h5"),
                                       test::quote(dir / "d1.h5"), test::quote(dir / "p1.h5"));
  const auto next = cli(fmt::format("plan {} {} --out {}", test::quote(modelled), data, test::quote(dir / "p2.h5")));
  EXPECT_NE(next.out.find("\"gp_warm_start\":true"), std::string::npos) << next.out;
  const auto other = cli(fmt::format("plan {} {} --out {}", test::quote(bare), data, test::quote(dir / "p2_bare.h5")));
  EXPECT_NE(other.out.find("\"gp_warm_start\":false"), std::string::npos) << other.out;
  std::filesystem::remove_all(dir);
}

TEST(ConfigModelCli, AConfigNamesItsSimulatorAndWorldByModelFilesAndBadOnesAreRefused) {
  const auto folder = test::temporary_dir("config_model");
  write_world(folder);
  test::write_text(folder / "quadrotor.toml", "[model]\nsystem = \"quadrotor\"\n");
  test::write_text(folder / "delayed.toml", "[model]\nsystem = \"cartpole\"\n[effects]\ninput_delay = 1.0\n");
  // Values a million times the model's own scale: no physical model (a pole of 1e300 m, a gain of 1e308).
  test::write_text(folder / "long.toml", "[model]\nsystem = \"cartpole\"\n[parameters]\npole_length = 1e300\n");
  test::write_text(folder / "gain.toml", "[model]\nsystem = \"cartpole\"\n[effects]\nactuator_gain = 1e308\n");
  const std::string source = (folder / "c.toml").string();
  // The simulator of `run`, by a path relative to the config; the stored text names it absolutely.
  const RunConfig run = parse_run_config("cartpole", "[system]\nmodel = \"world.toml\"\n", source);
  EXPECT_EQ(run.simulator.preset, Preset::RealWorld);
  EXPECT_EQ(run.simulator.forces.size(), 1u);
  EXPECT_NE(run.text.find((folder / "world.toml").string()), std::string::npos);
  const auto error_of = [&](const std::string& text) {
    try {
      (void)parse_run_config("cartpole", text, source);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  expect_holds(error_of("[system]\nmodel = \"quadrotor.toml\"\n"),
                   {"c.toml:line 2: field 'system.model'", "field 'model.system': is 'quadrotor'", "'cartpole'"});
  expect_holds(error_of("[system]\nmodel = \"delayed.toml\"\n"), {"field 'system.model'", "input delay of 1"});
  expect_holds(error_of("[system]\nmodel = \"none.toml\"\n"), {"field 'system.model'", "none.toml"});
  expect_holds(error_of("[diagnosis]\nafter_round = 4\n"), {"field 'diagnosis.after_round'", "from 0 to 3"});
  expect_holds(error_of("[system]\nmodel = \"long.toml\"\n"),
               {"field 'system.model'", "long.toml:line 4: field 'parameters.pole_length'",
                "pole_length = 1e+300; expected a finite value in [1e-06, 1e+06] m"});
  expect_holds(error_of("[world]\nmodel = \"gain.toml\"\n"),
               {"field 'world.model'", "gain.toml:line 4: field 'effects.actuator_gain'", "[0, 1e+06]"});
  expect_holds(error_of("[world]\nparameters = { pole_length = 1e300 }\n"),
               {"field 'world.parameters.pole_length'", "expected a finite value in [1e-06, 1e+06] m"});
  expect_holds(error_of("[diagnosis]\nafter_round = 0\nevery = 1\n"), {"diagnosis.every"});
  // --iterations (and a sweep's `iterations`, Python's run(iterations=)) fewer than after_round needs:
  // refused, where the loop would never diagnose; more are kept in the stored config, which says what ran.
  const RunConfig late = parse_run_config("cartpole", "[diagnosis]\nafter_round = 1\n", source);
  try {
    (void)with_iterations(late, 1, "--iterations");
    ADD_FAILURE() << "after_round 1 accepted with 1 iteration";
  } catch (const InputError& e) {
    expect_holds(e.what(), {"--iterations 1: the config's diagnosis.after_round is 1", "rounds are 0 to 0"});
  }
  const RunConfig longer = with_iterations(late, 6, "--iterations");
  EXPECT_EQ(longer.iterations, 6);
  EXPECT_EQ(parse_run_config("cartpole", longer.text, "stored").iterations, 6);

  // `solve` and `plan`: [system] model is the simulator, instead of a preset.
  const auto solve = folder / "solve.toml";
  std::string plan = test::kTinyPlan;
  const std::string preset = "preset = \"sim\"";
  test::write_text(solve, plan.replace(plan.find(preset), preset.size(), "model = \"world.toml\""));
  const SolveConfig config = read_plan_config(solve).problem;
  EXPECT_EQ(config.simulator.forces.size(), 1u);
  const Vector x = Vector::Zero(4), u = Vector::Zero(1);
  Vector with_friction(4), world_step(4);
  make_solve_model(config)->step(x, u, with_friction);
  make_step_model(run.simulator.build(config.noise), config.integrator, config.dt, config.substeps)->step(x, u, world_step);
  EXPECT_EQ(with_friction, world_step);

  // Declared user effects are part of the simulator: a constant force declared on the cart's x steps as
  // the library's external force on the cart, and unlike the bare preset.
  test::write_text(folder / "declared.toml", "[model]\nsystem = \"cartpole\"\n[[user_effects]]\nname = \"push\"\n"
                                             "coordinate = \"x\"\nterms = [\"1\"]\n[effects]\npush = 2.0\n");
  test::write_text(folder / "library.toml", "[model]\nsystem = \"cartpole\"\n[effects]\nexternal_force_x = 2.0\n");
  const auto step_of = [&](const std::string& model) {
    std::string text = test::kTinyPlan;
    const auto config = test::write_text(folder / "step.toml", text.replace(text.find(preset), preset.size(), model));
    Vector next(4);
    make_solve_model(read_plan_config(config).problem)->step((Vector(4) << 0.1, 0.2, 0.3, 0.4).finished(), u, next);
    return next;
  };
  const Vector declared = step_of("model = \"declared.toml\""), library = step_of("model = \"library.toml\"");
  EXPECT_TRUE(declared.isApprox(library, 1e-12)) << declared.transpose() << " vs " << library.transpose();
  EXPECT_GT((declared - step_of(preset)).norm(), 1e-3);

  // From the command line: exit 2 naming the config's field and the model file's line and field.
  test::write_text(folder / "negative.toml", "[model]\nsystem = \"cartpole\"\n[parameters]\npole_length = -1.0\n");
  test::write_text(folder / "unknown.toml", "[model]\nsystem = \"cartpole\"\n[effects]\nwind = 1.0\n");
  for (const auto& [model, expected] : {std::pair{"negative.toml", "negative.toml:line 4: field 'parameters.pole_length'"},
                                        std::pair{"unknown.toml", "unknown.toml:line 4: field 'effects.wind': unknown effect"},
                                        std::pair{"quadrotor.toml", "field 'model.system': is 'quadrotor'"}}) {
    const auto config = test::write_text(folder / "bad_plan.toml", plan.replace(plan.find("model = "), plan.find('\n', plan.find("model = ")) - plan.find("model = "),
                                                                                 fmt::format("model = \"{}\"", model)));
    const auto r = test::run_cli("plan " + test::quote(config) + " --out " + test::quote(folder / "p.h5"));
    EXPECT_EQ(r.status, 2) << model;
    expect_holds(r.err, {"bad_plan.toml:line 3: field 'system.model'", expected});
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace gpilqg
