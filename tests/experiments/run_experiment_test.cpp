/// `gpilqg run` end to end on a tiny cart-pole configuration: the evaluation agrees with the solver
/// where it must (no noise, true model), seeded runs repeat bit for bit, every algorithm sees the data
/// the protocol promises (PDDP the data of gp_ilqg, a transfer task the previous task's data), the
/// result file has the documented layout, and the plot script draws it.

#include "gpilqg/experiments/run_experiment.hpp"

#include <fstream>
#include <unistd.h>

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include "gpilqg/experiments/algorithm_runs.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/plot_script.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "gpilqg/gp/residual_model.hpp"
#include "finite_checks.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

using test::kTinyRun;

RunResults tiny_run(std::vector<std::uint64_t> seeds) {
  RunOptions options;
  options.seeds = std::move(seeds);
  return run_experiment(parse_run_config("cartpole", kTinyRun, "tiny.toml"), options);
}

const AlgorithmRun& find(const TaskResults& task, std::size_t seed, const std::string& name) {
  for (const auto& run : task.seeds.at(seed))
    if (run.name == name) return run;
  throw std::runtime_error("no algorithm " + name);
}

TEST(RunExperiment, SolvesStopAtTheirIterationCapNotAtAWallTime) {
  // The quadrotor's PDDP iterations take 3 to 50 s each (N = 160 to 640), and its full-horizon
  // Robust-iLQG solves on 600 GP points 40 to 60 s: with DdpOptions' default 60 s wall-time cap
  // (a run's [solver] has no max_seconds) they stopped part-way, at a point set by the machine's load.
  const RunConfig config = load_run_config("quadrotor", std::nullopt);
  EXPECT_GE(config.solver.max_seconds, 1e12);  // gp_ilqg's solves and MPC windows: never the limit
  EXPECT_NO_THROW(config.solver.validate());
  const DdpOptions options = pddp_solver_options(config);
  EXPECT_EQ(options.max_iterations, config.pddp_max_iterations);
  EXPECT_GE(options.max_seconds, 1e12);  // never the limit
  EXPECT_NO_THROW(options.validate());
  EXPECT_EQ(options.gradient_tolerance, config.solver.gradient_tolerance);
  EXPECT_EQ(options.cost_tolerance, config.solver.cost_tolerance);
}

TEST(RunExperiment, WithoutNoiseTheTrueModelsPolicyCostsWhatItsSolverPredicted) {
  // With no process or observation noise, the closed loop on the world retraces the plan made on the
  // world, so the evaluated cost (rollout code) equals the solver's predicted cost (DDP code).
  RunConfig config = parse_run_config("cartpole", kTinyRun, "tiny.toml");
  config.noise.multiplicative_std = Vector::Zero(1);
  config.observation_std = Vector::Zero(4);
  const RunModels models = make_run_models(config);
  const QuadraticCost cost = make_task_cost(config, config.tasks[0]);
  const TaskContext context{config, config.tasks[0], 0, models, cost, nullptr};
  const AlgorithmRun run = run_fixed_model(context, "ilqg_real", models.world, 1);
  const IterationRecord& r = run.iterations.front();
  EXPECT_NEAR(r.evaluation.mean_cost, r.plan.predicted_cost, 1e-9 * r.plan.predicted_cost);
  EXPECT_EQ(r.evaluation.costs[0], r.evaluation.costs[1]);
  ASSERT_EQ(run.iterations.size(), 3u);
  EXPECT_TRUE(run.iterations[2].repeated);
}

TEST(RunExperiment, AlgorithmsSeeTheDataTheProtocolPromisesAndSeedsRepeat) {
  const RunResults a = tiny_run({5});
  const RunResults b = tiny_run({5, 6});
  ASSERT_EQ(a.tasks.size(), 2u);
  const std::vector<std::string> expected = {"ilqg_real", "ilqg_sim", "gp_ilqg", "pddp", "pddp_own"};
  ASSERT_EQ(a.tasks[0].algorithms, expected);

  for (std::size_t t = 0; t < 2; ++t) {
    // The same seed gives the same run, bit for bit (seed 5 is the first seed of both runs).
    for (std::size_t alg = 0; alg < expected.size(); ++alg)
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_EQ(a.tasks[t].seeds[0][alg].iterations[k].evaluation.costs,
                  b.tasks[t].seeds[0][alg].iterations[k].evaluation.costs)
            << expected[alg] << " task " << t << " iteration " << k;
    // PDDP is trained at every iteration on exactly the data gp_ilqg had.
    const auto& gp = find(a.tasks[t], 0, "gp_ilqg");
    const auto& pddp = find(a.tasks[t], 0, "pddp");
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(pddp.iterations[k].data_rows, gp.iterations[k].data_rows);
  }
  // Another seed collects other data.
  const auto& gp5 = find(b.tasks[0], 0, "gp_ilqg");
  const auto& gp6 = find(b.tasks[0], 1, "gp_ilqg");
  ASSERT_EQ(gp5.data.size(), gp6.data.size());
  EXPECT_GT((gp5.data.x - gp6.data.x).cwiseAbs().maxCoeff(), 0.0);

  // Task 1: gp_ilqg starts with no data (iLQG on the simulator = ilqg_sim), then one rollout of 15
  // transitions per round. Task 2 starts from all of task 1's data (transfer).
  const auto& first = find(a.tasks[0], 0, "gp_ilqg");
  EXPECT_EQ(first.iterations[0].data_rows, 0);
  EXPECT_EQ(first.iterations[0].evaluation.costs, find(a.tasks[0], 0, "ilqg_sim").iterations[0].evaluation.costs);
  if (first.converged_at < 0) {
    EXPECT_EQ(first.data.size(), 2 * 15);
  }
  const auto& second = find(a.tasks[1], 0, "gp_ilqg");
  EXPECT_EQ(second.iterations[0].data_rows, first.data.size());
  EXPECT_FALSE(second.iterations[0].hyperparameters.empty());  // it starts with a learned model
  EXPECT_EQ(find(a.tasks[0], 0, "pddp_own").iterations[0].data_rows, 15);  // its random episode
  for (const auto& run : a.tasks[1].seeds[0])
    for (const auto& record : run.iterations) EXPECT_TRUE(std::isfinite(record.evaluation.mean_cost)) << run.name;
}

TEST(RunExperiment, ModelSliceReturnsToTheSimulatorFarFromTheData) {
  const RunResults r = tiny_run({2});
  const ModelSlice& s = r.tasks[0].slice;
  ASSERT_EQ(s.grid.size(), 401);
  const auto& gp = find(r.tasks[0], 0, "gp_ilqg");
  const auto* model = dynamic_cast<const gp::ResidualModel*>(gp.final_model.get());
  ASSERT_NE(model, nullptr);
  // kSliceMargin length-scales beyond the data on either side, where every measurement's covariance
  // with the slice is below sf^2 exp(-8): the corrected model is the simulator and the standard
  // deviation is the prior's sf (the paper's Figure 1).
  const double sf = std::sqrt(model->output(s.output).prior_variance());
  for (const Eigen::Index end : {Eigen::Index{0}, s.grid.size() - 1}) {
    EXPECT_NEAR(s.mean(end), s.simulator(end), 1e-2 * sf);
    EXPECT_NEAR(s.std(end), sf, 1e-2 * sf);
  }
  EXPECT_EQ(s.data_residual.size(), s.data_z.size());
  EXPECT_LT(s.std.minCoeff(), 0.5 * sf);  // and it is corrected near the data
}

std::vector<hsize_t> shape_of(const H5::H5File& file, const std::string& path) {
  const H5::DataSpace space = file.openDataSet(path).getSpace();
  std::vector<hsize_t> dims(static_cast<std::size_t>(space.getSimpleExtentNdims()));
  space.getSimpleExtentDims(dims.data());
  return dims;
}

TEST(RunExperiment, ResultFileHasTheDocumentedLayoutAndPlots) {
  const RunResults r = tiny_run({3, 4});
  const auto dir = test::temporary_dir("run_results");
  const auto file = dir / "run.h5";
  write_run_results(file, r);
  H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  for (const char* attribute : {"schema_version", "gpilqg_version", "config", "seed", "created", "system"})
    EXPECT_TRUE(h5.attrExists(attribute)) << attribute;
  using Shape = std::vector<hsize_t>;
  EXPECT_EQ(shape_of(h5, "/seeds"), Shape({2}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/cost"), Shape({3, 2}));
  EXPECT_EQ(shape_of(h5, "/first/pddp/normalised_cost"), Shape({3, 2}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/evaluation_costs"), Shape({3, 2, 2}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/iter_1/x"), Shape({2, 4, 16}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/iter_1/u"), Shape({2, 1, 15}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/iter_1/K"), Shape({2, 15, 1, 4}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/iter_2/predicted_cost"), Shape({2}));
  EXPECT_EQ(shape_of(h5, "/first/gp_ilqg/gp/theta_dot/hyper"), Shape({3, 2, 7}));
  EXPECT_EQ(shape_of(h5, "/second/figure1/grid"), Shape({401}));
  EXPECT_EQ(shape_of(h5, "/second/figure1/length_scales"), Shape({5}));
  EXPECT_EQ(shape_of(h5, "/second/figure1/data_residual"), shape_of(h5, "/second/figure1/data_z"));
  const hsize_t rows = static_cast<hsize_t>(find(r.tasks[1], 0, "gp_ilqg").data.size() +
                                            find(r.tasks[1], 1, "gp_ilqg").data.size());
  EXPECT_EQ(shape_of(h5, "/second/data/dx"), Shape({rows, 4}));
  Matrix normalised(3, 2);
  {
    RowMajorMatrix buffer(3, 2);
    h5.openDataSet("/first/ilqg_real/normalised_cost").read(buffer.data(), H5::PredType::NATIVE_DOUBLE);
    normalised = buffer;
  }
  EXPECT_MATRIX_NEAR(normalised, Matrix::Ones(3, 2), 0.0);
  h5.close();
  for (const auto& entry : std::filesystem::directory_iterator(dir))  // no temporary left behind
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();

  // The figures come from the file alone (skipped where Debian's matplotlib is missing).
  if (std::system("/usr/bin/python3 -c 'import matplotlib, h5py' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 lacks matplotlib or h5py";
  run_plot_script("plot_run.py", file, dir / "figures");
  for (const char* png : {"first_cost.png", "second_cost.png", "first_controls.png", "first_gp_slice.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "figures" / png)) << png;
}

TEST(RunExperiment, ComparesGpBackendsOnTheSameSeedsAndLinksTheFirstAsGpIlqg) {
  RunConfig config = parse_run_config("cartpole", kTinyRun, "tiny.toml");
  config.tasks.resize(1);
  config.iterations = 1;
  config.pddp = false;
  config.gp.backend_settings.inducing = 10;
  config.gp.backend_settings.frequencies = 10;
  RunOptions options;
  options.seeds = {7};
  options.backends = {"exact", "fitc", "ssgp"};
  const RunResults r = run_experiment(config, options);
  EXPECT_EQ(r.tasks[0].algorithms,
            (std::vector<std::string>{"ilqg_real", "ilqg_sim", "gp_ilqg_exact", "gp_ilqg_fitc", "gp_ilqg_ssgp"}));
  // Same seed, same start: every backend's iteration 0 is iLQG on the simulator, the same policy.
  const auto& exact = find(r.tasks[0], 0, "gp_ilqg_exact");
  const auto& ssgp = find(r.tasks[0], 0, "gp_ilqg_ssgp");
  EXPECT_EQ(exact.iterations[0].evaluation.costs, ssgp.iterations[0].evaluation.costs);
  EXPECT_EQ(ssgp.iterations[1].hyperparameters.size(), 4u);  // it fitted its own GPs
  const auto file = test::temporary_dir("run_backends") / "run.h5";
  write_run_results(file, r);
  H5::H5File h5(file.string(), H5F_ACC_RDONLY);
  RowMajorMatrix linked(2, 1), direct(2, 1);
  h5.openDataSet("/first/gp_ilqg/cost").read(linked.data(), H5::PredType::NATIVE_DOUBLE);
  h5.openDataSet("/first/gp_ilqg_exact/cost").read(direct.data(), H5::PredType::NATIVE_DOUBLE);
  EXPECT_EQ(linked, direct);
}

// gp.known_noise: every GP takes the noise the simulator predicts at each transition as known and
// learns the rest; its learned noise then falls below the floor the same data give without it (the
// floor is the least of that noise), and no floor is recorded. A backend that does not take it is refused.
TEST(RunExperiment, KnownNoiseGpsLearnOnlyTheRestAndOtherBackendsAreRefused) {
  RunConfig config = parse_run_config("cartpole", kTinyRun, "tiny.toml");
  config.tasks.resize(1);
  config.iterations = 2;
  config.pddp = false;
  RunOptions options;
  options.seeds = {7};
  const RunResults floor = run_experiment(config, options);
  config.gp.known_noise = true;
  const RunResults known = run_experiment(config, options);
  const IterationRecord& with_floor = find(floor.tasks[0], 0, "gp_ilqg").iterations[1];
  const IterationRecord& with_known = find(known.tasks[0], 0, "gp_ilqg").iterations[1];
  ASSERT_EQ(with_known.hyperparameters.size(), 4u);
  EXPECT_EQ(with_known.noise_floor, Vector::Zero(4));
  EXPECT_GT(with_floor.noise_floor.minCoeff(), 0.0);
  const int D = 5;
  for (int i = 0; i < 4; ++i) {
    const double learned = std::exp(with_known.hyperparameters[static_cast<std::size_t>(i)](D + 1));
    EXPECT_LT(learned, with_floor.noise_floor(i)) << "state " << i;
  }
  EXPECT_TRUE(std::isfinite(find(known.tasks[0], 0, "gp_ilqg").iterations[1].evaluation.mean_cost));

  // The compact-support backend does not take it (GpBackend::takes_known_noise): refused by name.
  options.backends = {"exact", "compact"};
  try {
    (void)run_experiment(config, options);
    ADD_FAILURE() << "known noise with compact was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--backends: 'compact' with the config's gp.known_noise = true"), std::string::npos)
        << e.what();
  }
  std::string compact = kTinyRun;
  compact.replace(compact.find("[gp]\n"), 5, "[gp]\nbackend = \"compact\"\nknown_noise = true\n");
  try {
    (void)parse_run_config("cartpole", compact, "compact.toml");
    ADD_FAILURE() << "a config with compact and known noise was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'gp.known_noise': is true with backend 'compact'"), std::string::npos)
        << e.what();
  }
  std::string fitc = kTinyRun;
  fitc.replace(fitc.find("[gp]\n"), 5, "[gp]\nbackend = \"fitc\"\nknown_noise = true\n");
  EXPECT_TRUE(parse_run_config("cartpole", fitc, "fitc.toml").gp.known_noise);
}

TEST(RunCli, AStartThatDivergesIsRecordedAndTheResultStaysFinite) {
  // x0 within the config's bound (1e12) but diverging at once: every solve's initial rollout and
  // every real-world rollout diverge. Once the predicted costs were written as inf.
  const auto dir = test::temporary_dir("run_diverging_start");
  std::string text = kTinyRun;
  text.replace(text.find("x0 = [0.0, 0.0, 0.3, 0.0]"), 25, "x0 = [1e11, 0.0, 0.3, 1e11]");
  std::ofstream(dir / "far.toml") << text;
  const auto r = test::run_cli("run cartpole --config " + (dir / "far.toml").string() + " --iterations 1 --out " +
                               (dir / "r.h5").string() + " --no-plots");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("first ilqg_real iteration 0/1: cost "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" diverged ("), std::string::npos) << r.err;  // "..., 2 diverged (data ..."
  EXPECT_TRUE(test::hdf5_datasets_finite(dir / "r.h5"));
  H5::H5File h5((dir / "r.h5").string(), H5F_ACC_RDONLY);
  const H5::DataSet diverged = h5.openDataSet("/first/ilqg_real/diverged");
  std::vector<double> counts(static_cast<std::size_t>(diverged.getSpace().getSimpleExtentNpoints()));
  diverged.read(counts.data(), H5::PredType::NATIVE_DOUBLE);
  ASSERT_FALSE(counts.empty());
  EXPECT_GT(counts.front(), 0.0);  // the status is recorded
}

TEST(RunCli, RunsFromAConfigFileAndRejectsBadOptions) {
  const auto dir = test::temporary_dir("run_cli");
  {
    std::ofstream(dir / "tiny.toml") << kTinyRun << "[pddp]\n";
  }
  // A repeated table is a TOML error: named with its file and line.
  const auto bad = test::run_cli("run cartpole --config " + (dir / "tiny.toml").string() + " --no-plots");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("tiny.toml:line"), std::string::npos) << bad.err;
  {
    std::ofstream(dir / "tiny.toml") << kTinyRun;
  }
  const auto ok = test::run_cli("run cartpole --config " + (dir / "tiny.toml").string() + " --iterations 1 --out " +
                                (dir / "r.h5").string() + " --no-plots");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "r.h5"));
  EXPECT_NE(ok.out.find("gp_ilqg"), std::string::npos) << ok.out;
  EXPECT_NE(ok.err.find("first gp_ilqg iteration 1/1"), std::string::npos) << ok.err;  // progress on stderr

  const auto backends = test::run_cli("run cartpole --backends exact,gpflow --no-plots");
  EXPECT_EQ(backends.status, 2);
  EXPECT_NE(backends.err.find("unknown backend 'gpflow'"), std::string::npos) << backends.err;
  const auto seeds = test::run_cli("run cartpole --seeds 0 --no-plots");
  EXPECT_EQ(seeds.status, 2);
  const auto system = test::run_cli("run pendulum");
  EXPECT_EQ(system.status, 2);
}

}  // namespace
}  // namespace gpilqg
