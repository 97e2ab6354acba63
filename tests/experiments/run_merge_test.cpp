/// `gpilqg merge` (run_merge.hpp): result files of separate runs for disjoint seeds merge into the
/// file one run of all the seeds writes, bit for bit but the wall-clock times and `created`, whatever
/// the order of the parts; runs of the same seeds with different --backends merge into the file of one
/// run with both backends when their shared algorithms are equal (PDDP disabled), and are refused when
/// they are not (PDDP plans on the first backend's data); every refusal names the files and the field.

#include "gpilqg/experiments/run_merge.hpp"

#include <fstream>
#include <functional>
#include <limits>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_experiment.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "result_files.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

/// The TOML `text` with `line` added to its table [section] (a table cannot be opened twice).
std::string with_line(std::string text, const std::string& section, const std::string& line) {
  const std::string header = "[" + section + "]\n";
  text.insert(text.find(header) + header.size(), line + "\n");
  return text;
}

/// The tiny config for runs with --backends: FITC with 10 inducing points (fewer than the data of
/// the first round).
std::string tiny_text_for_backends() { return with_line(test::kTinyRun, "gp", "inducing = 10"); }

RunResults run_seeds(const RunConfig& config, std::vector<std::uint64_t> seeds, std::vector<std::string> backends = {}) {
  RunOptions options;
  options.seeds = std::move(seeds);
  options.backends = std::move(backends);
  return run_experiment(config, options);
}

fs::path written(const fs::path& file, const RunResults& results) {
  write_run_results(file, results);
  return file;
}

/// The message of the InputError the merge throws; "merged" when it merges.
std::string refusal(const std::vector<fs::path>& parts, const fs::path& out) {
  try {
    merge_run_results(parts, out);
  } catch (const InputError& e) {
    return e.what();
  }
  return "merged";
}

std::size_t index_of(const TaskResults& task, const std::string& algorithm) {
  return static_cast<std::size_t>(std::find(task.algorithms.begin(), task.algorithms.end(), algorithm) - task.algorithms.begin());
}

/// Runs of the tiny config shared by the tests: seeds 1, 2 and 3 each on its own, seeds 1-2 and 1-3
/// in one run each.
class RunMerge : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const RunConfig config = parse_run_config("cartpole", test::kTinyRun, "tiny.toml");
    for (const std::uint64_t seed : {1, 2, 3}) single_.push_back(run_seeds(config, {seed}));
    two_ = run_seeds(config, {1, 2});
    three_ = run_seeds(config, {1, 2, 3});
  }
  static void TearDownTestSuite() { single_.clear(); }

  void SetUp() override {
    dir_ = test::temporary_dir("run_merge");
    for (std::size_t s = 0; s < single_.size(); ++s) parts_.push_back(written(dir_ / fmt::format("seed_{}.h5", s + 1), single_[s]));
  }
  void TearDown() override { fs::remove_all(dir_); }

  static inline std::vector<RunResults> single_;
  static inline RunResults two_, three_;
  fs::path dir_;
  std::vector<fs::path> parts_;  ///< seed_1.h5, seed_2.h5, seed_3.h5
};
/// The same parts for the tests that run the program (ctest label cli).
using RunMergeCli = RunMerge;

TEST(RunMergeLayout, EveryDatasetOfAnAlgorithmHasItsSeedAxis) {
  for (const char* name : {"cost", "normalised_cost", "time_fit", "policy_change", "evaluation_costs", "gp/theta/hyper", "gp/x/fitted"})
    EXPECT_EQ(seed_axis(name), std::optional<std::size_t>(1)) << name;
  for (const char* name : {"converged_at", "iter_0/x", "iter_12/K", "iter_3/solve_time", "iter_1/eval_u"})
    EXPECT_EQ(seed_axis(name), std::optional<std::size_t>(0)) << name;
  for (const char* name : {"bogus", "iter_x/K", "iter_/K", "iter_1/bogus", "gp/hyper", "gp/theta/other", "data/x", "figure1/grid"})
    EXPECT_EQ(seed_axis(name), std::nullopt) << name;
  for (const char* name : {"time_fit", "time_solve", "time_rollouts", "time_evaluation", "iter_4/solve_time"})
    EXPECT_TRUE(is_wall_clock_time(name)) << name;
  for (const char* name : {"cost", "iter_4/predicted_cost", "converged_at"}) EXPECT_FALSE(is_wall_clock_time(name)) << name;
}

TEST_F(RunMerge, SeedsRunSeparatelyMergeIntoTheFileOfOneRunInEitherOrder) {
  const fs::path one_run = written(dir_ / "one_run.h5", two_);
  const MergeSummary summary = merge_run_results({parts_[0], parts_[1]}, dir_ / "merged.h5");
  test::expect_same_result_files(dir_ / "merged.h5", one_run);
  EXPECT_EQ(summary.parts, 2u);
  EXPECT_EQ(summary.seeds, (std::vector<std::uint64_t>{1, 2}));
  ASSERT_EQ(summary.tasks.size(), 2u);
  EXPECT_EQ(summary.tasks[0].name, "first");
  EXPECT_EQ(summary.tasks[0].algorithms, two_.tasks[0].algorithms);
  EXPECT_GT(summary.tasks[0].data_rows, 0u);

  merge_run_results({parts_[1], parts_[0]}, dir_ / "reversed.h5");
  test::expect_same_result_files(dir_ / "reversed.h5", one_run);
}

TEST_F(RunMerge, ThreePartsMergeIntoTheFileOfOneRun) {
  const fs::path one_run = written(dir_ / "one_run.h5", three_);
  merge_run_results({parts_[2], parts_[0], parts_[1]}, dir_ / "merged.h5");
  test::expect_same_result_files(dir_ / "merged.h5", one_run);
  // A merged file is a part like any other.
  merge_run_results({parts_[0], parts_[1]}, dir_ / "first_two.h5");
  merge_run_results({dir_ / "first_two.h5", parts_[2]}, dir_ / "merged_again.h5");
  test::expect_same_result_files(dir_ / "merged_again.h5", one_run);
}

TEST_F(RunMerge, ASeedHeldTwiceIsKeptOnceWhenOnlyItsWallClockTimesDiffer) {
  RunResults slower = single_[0];
  for (auto& task : slower.tasks)
    for (auto& runs : task.seeds)
      for (auto& run : runs)
        for (auto& record : run.iterations) {
          record.fit_seconds += 1.0, record.rollout_seconds += 1.0, record.evaluation.seconds += 1.0;
          record.plan.solve_seconds += 1.0;
        }
  const fs::path again = written(dir_ / "seed_1_again.h5", slower);
  merge_run_results({parts_[0], again, parts_[1]}, dir_ / "merged.h5");
  test::expect_same_result_files(dir_ / "merged.h5", written(dir_ / "one_run.h5", two_));

  RunResults changed = single_[0];
  TaskResults& task = changed.tasks[0];
  task.seeds[0][index_of(task, "gp_ilqg")].iterations[1].plan.predicted_cost += 1e-9;
  const fs::path other = written(dir_ / "seed_1_changed.h5", changed);
  const std::string message = refusal({parts_[0], parts_[1], other}, dir_ / "refused.h5");
  EXPECT_NE(message.find(fmt::format("{} and {} both hold seed 1 of gp_ilqg on task first", parts_[0].string(), other.string())),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("iter_1/predicted_cost"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(dir_ / "refused.h5"));
}

// The same config naming a model file whose text differs between the parts: two simulators.
TEST_F(RunMerge, PartsWhoseConfigNamedFilesThatReadDifferentlyAreRefused) {
  RunResults first = single_[0], second = single_[1];
  first.config.files_text = "# the config's system.model = /a/sm.toml\n[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n";
  second.config.files_text = "# the config's system.model = /a/sm.toml\n[model]\nsystem = \"cartpole\"\npreset = \"real\"\n";
  const fs::path a = written(dir_ / "model_a.h5", first), b = written(dir_ / "model_b.h5", second);
  const std::string message = refusal({a, b}, dir_ / "merged.h5");
  EXPECT_NE(message.find(fmt::format("{}: the files its config names read differently from {}'s (the config's "
                                     "system.model = /a/sm.toml, line 3: \"preset = \"real\"\" here, \"preset = \"sim\"\" there)",
                                     b.string(), a.string())),
            std::string::npos)
      << message;
  EXPECT_FALSE(fs::exists(dir_ / "merged.h5"));
}

TEST_F(RunMerge, PartsOfADifferentConfigAreRefusedNamingTheField) {
  RunResults other_limit = single_[1];
  other_limit.config.text = parse_run_config("cartpole", std::string(test::kTinyRun) + "[control]\nu_max = [9.0]\n", "t.toml").text;
  const fs::path limit = written(dir_ / "limit.h5", other_limit);
  const std::string message = refusal({parts_[0], limit}, dir_ / "merged.h5");
  EXPECT_NE(message.find(fmt::format("{}: its config differs from {}'s in control.u_max ([ 9.0 ] here, [ 25.0 ] there)", limit.string(),
                                     parts_[0].string())),
            std::string::npos)
      << message;

  RunResults other_task = single_[1];
  std::string text = test::kTinyRun;
  text.replace(text.find("x0 = [0.0, 0.0, -0.3, 0.0]"), 26, "x0 = [0.0, 0.0, -0.2, 0.0]");
  other_task.config.text = parse_run_config("cartpole", text, "t.toml").text;
  const std::string task_message = refusal({parts_[0], written(dir_ / "task.h5", other_task)}, dir_ / "merged.h5");
  EXPECT_NE(task_message.find("config differs from"), std::string::npos) << task_message;
  EXPECT_NE(task_message.find("in tasks[1].x0 ("), std::string::npos) << task_message;
  EXPECT_NE(task_message.find("-0.2"), std::string::npos) << task_message;

  RunResults more_tasks = single_[1];
  more_tasks.config.text = parse_run_config("cartpole", std::string(test::kTinyRun) + R"(
[[tasks]]
name = "third"
x0 = [0.0, 0.0, 0.1, 0.0]
goal = [0.0, 0.0, 0.0, 0.0]
horizon = 15
Q = [1.0, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
track_line = false
transfer = false
)", "t.toml").text;
  const std::string tasks_message = refusal({parts_[0], written(dir_ / "tasks.h5", more_tasks)}, dir_ / "merged.h5");
  EXPECT_NE(tasks_message.find("in tasks (3 tables here, 2 tables there)"), std::string::npos) << tasks_message;
}

TEST_F(RunMerge, AnAlgorithmWithoutEverySeedIsRefused) {
  RunResults fewer = single_[1];
  for (TaskResults& task : fewer.tasks) {
    const std::size_t a = index_of(task, "pddp_own");
    task.algorithms.erase(task.algorithms.begin() + static_cast<std::ptrdiff_t>(a));
    for (auto& runs : task.seeds) runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(a));
  }
  const std::string message = refusal({parts_[0], written(dir_ / "fewer.h5", fewer)}, dir_ / "merged.h5");
  EXPECT_NE(message.find("pddp_own on task first has seeds 1 but the merged file has seeds 1, 2"), std::string::npos) << message;
  EXPECT_NE(message.find(parts_[0].string()), std::string::npos) << message;
}

TEST_F(RunMerge, PartsOfADifferentIterationCountAreRefused) {
  RunResults shorter = single_[1];
  for (TaskResults& task : shorter.tasks)
    for (auto& runs : task.seeds)
      for (auto& run : runs) run.iterations.pop_back();
  const fs::path part = written(dir_ / "shorter.h5", shorter);
  const std::string message = refusal({parts_[0], part}, dir_ / "merged.h5");
  EXPECT_NE(message.find(part.string() + ": dataset '/first/ilqg_real/iter_2/"), std::string::npos) << message;
  EXPECT_NE(message.find("is missing"), std::string::npos) << message;
}

TEST_F(RunMerge, FilesThatAreNotDistinctResultPartsAreRefused) {
  EXPECT_NE(refusal({parts_[0]}, dir_ / "merged.h5").find("1 file given; expected two or more"), std::string::npos);
  EXPECT_NE(refusal({parts_[0], parts_[1]}, parts_[1]).find(fmt::format("the output {} is one of the files to merge", parts_[1].string())),
            std::string::npos);
  EXPECT_NE(refusal({parts_[0], parts_[0]}, dir_ / "merged.h5").find("are the same file"), std::string::npos);

  const fs::path other = dir_ / "other.h5";
  {
    Hdf5Writer h5(other);
    h5.write_vector("/x", std::vector<double>{1.0, 2.0});
    h5.close();
  }
  const std::string message = refusal({parts_[0], other}, dir_ / "merged.h5");
  EXPECT_EQ(message, other.string() + ": no 'schema_version' attribute; expected a result file of `gpilqg run`");
  const fs::path text = dir_ / "notes.h5";
  std::ofstream(text) << "not HDF5\n";
  EXPECT_EQ(refusal({text, parts_[0]}, dir_ / "merged.h5"), text.string() + ": not an HDF5 file; expected a result file of `gpilqg run`");
  EXPECT_NE(refusal({dir_ / "absent.h5", parts_[0]}, dir_ / "merged.h5").find("absent.h5"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "merged.h5"));
}

TEST_F(RunMergeCli, APartHoldingANaNOrAnInfIsRefusedNamingTheDatasetAndTheEntry) {
  struct Case {
    const char* name;
    std::function<void(IterationRecord&)> damage;
    int iteration;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"nan_cost", [](IterationRecord& r) { r.evaluation.mean_cost = std::numeric_limits<double>::quiet_NaN(); }, 1,
       "dataset '/first/gp_ilqg/cost' entry [1, 0] is nan; expected finite numbers"},
      {"inf_state", [](IterationRecord& r) { r.evaluation.example.x(2, 3) = std::numeric_limits<double>::infinity(); }, 0,
       "dataset '/first/gp_ilqg/iter_0/eval_x' entry [0, 2, 3] is inf; expected finite numbers"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    RunResults damaged = single_[1];
    TaskResults& task = damaged.tasks[0];
    c.damage(task.seeds[0][index_of(task, "gp_ilqg")].iterations[static_cast<std::size_t>(c.iteration)]);
    const fs::path part = written(dir_ / fmt::format("{}.h5", c.name), damaged);
    EXPECT_EQ(refusal({parts_[0], part}, dir_ / "merged.h5"), part.string() + ": " + c.message);
    const auto r = test::run_cli(fmt::format("merge '{}' '{}' --no-plots --out '{}'", parts_[0].string(), part.string(),
                                             (dir_ / "merged.h5").string()));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(part.string() + ": " + c.message), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "merged.h5"));
}

TEST_F(RunMergeCli, TheCommandMergesPrintsASummaryAndExitsTwoOnARefusal) {
  const auto quote = [](const fs::path& p) { return "'" + p.string() + "'"; };
  const fs::path merged = dir_ / "merged.h5";
  const auto done = test::run_cli("merge " + quote(parts_[0]) + " " + quote(parts_[1]) + " --out " + quote(merged) + " --no-plots");
  ASSERT_EQ(done.status, 0) << done.err;
  EXPECT_NE(done.out.find("merged 2 files: 2 seed(s) (1, 2)"), std::string::npos) << done.out;
  EXPECT_NE(done.out.find("first: ilqg_real, ilqg_sim, gp_ilqg, pddp, pddp_own"), std::string::npos) << done.out;
  test::expect_same_result_files(merged, written(dir_ / "one_run.h5", two_));

  const auto refused = test::run_cli("merge " + quote(parts_[0]) + " " + quote(parts_[1]) + " --out " + quote(parts_[0]) + " --no-plots");
  EXPECT_EQ(refused.status, 2);
  EXPECT_EQ(refused.err.rfind("error:", 0), 0u) << refused.err;
  EXPECT_NE(refused.err.find("is the same file as PART " + parts_[0].string() + ", an input of the command"), std::string::npos)
      << refused.err;
  const auto one = test::run_cli("merge " + quote(parts_[0]) + " --out " + quote(merged) + " --no-plots");
  EXPECT_EQ(one.status, 2);
  EXPECT_EQ(one.err.rfind("error:", 0), 0u) << one.err;
}

// ---- parts of the same seeds with different GP backends ------------------------------------------

TEST(RunMergeBackends, RunsOfOneBackendEachMergeIntoTheRunOfBothWithoutPddp) {
  // PDDP plans on the data of the first backend's GP-ILQG, so it differs between --backends exact
  // and --backends fitc; without it, the algorithms both runs hold (ilqg_real, ilqg_sim) are equal
  // and the merge is the run of both backends.
  const auto dir = test::temporary_dir("run_merge_backends");
  const RunConfig config = parse_run_config("cartpole", with_line(tiny_text_for_backends(), "pddp", "enabled = false"), "tiny.toml");
  const fs::path exact = written(dir / "exact.h5", run_seeds(config, {1, 2}, {"exact"}));
  const fs::path fitc = written(dir / "fitc.h5", run_seeds(config, {1, 2}, {"fitc"}));
  const fs::path both = written(dir / "both.h5", run_seeds(config, {1, 2}, {"exact", "fitc"}));
  const MergeSummary summary = merge_run_results({exact, fitc}, dir / "merged.h5");
  EXPECT_EQ(summary.tasks.at(0).algorithms, (std::vector<std::string>{"ilqg_real", "ilqg_sim", "gp_ilqg_exact", "gp_ilqg_fitc"}));
  test::expect_same_result_files(dir / "merged.h5", both);
  fs::remove_all(dir);
}

TEST(RunMergeBackends, RunsOfOneBackendEachWithPddpAreRefusedNamingPddp) {
  const auto dir = test::temporary_dir("run_merge_backends");
  const RunConfig config = parse_run_config("cartpole", tiny_text_for_backends(), "tiny.toml");
  const fs::path exact = written(dir / "exact.h5", run_seeds(config, {1}, {"exact"}));
  const fs::path fitc = written(dir / "fitc.h5", run_seeds(config, {1}, {"fitc"}));
  const std::string message = refusal({exact, fitc}, dir / "merged.h5");
  EXPECT_NE(message.find(fmt::format("{} and {} both hold seed 1 of pddp on task first", exact.string(), fitc.string())),
            std::string::npos)
      << message;
  // A run without --backends has an algorithm gp_ilqg where these have a link to one.
  const fs::path plain = written(dir / "plain.h5", run_seeds(config, {1}));
  const std::string plain_message = refusal({exact, plain}, dir / "merged.h5");
  EXPECT_NE(plain_message.find("parts run with and without --backends cannot be joined"), std::string::npos) << plain_message;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg
