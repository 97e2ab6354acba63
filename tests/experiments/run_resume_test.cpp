/// Resumable `gpilqg run` (run_checkpoint.hpp): a run stopped after any completed iteration and
/// resumed computes exactly what an uninterrupted run computes; the real program stops on SIGINT with
/// exit 130 and leaves a previous result file untouched, and survives SIGKILL at any moment; a
/// checkpoint refuses to serve a different run.

#include "gpilqg/experiments/run_checkpoint.hpp"

#include <chrono>
#include <csignal>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/experiments/config_model.hpp"
#include "gpilqg/experiments/run_results_io.hpp"
#include "finite_checks.hpp"
#include "result_files.hpp"
#include "same_run_results.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

extern char** environ;

namespace gpilqg {
namespace {

std::string read_file_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

RunOptions two_seeds() {
  RunOptions options;
  options.seeds = {3, 4};
  return options;
}

TEST(RunResume, StoppedAfterAnyIterationAndResumedEqualsAnUninterruptedRun) {
  const RunConfig config = test::tiny_run_config();
  const RunResults reference = run_experiment(config, two_seeds());

  // Count the saves of a whole run, then stop after a spread of them: fixed-model runs, the middle
  // of gp_ilqg's and PDDP's loops, the transfer task, the second seed, the very last save.
  const auto folder = test::temporary_dir("run_resume") / "run.h5.checkpoint";
  int total = 0;
  {
    RunOptions options = two_seeds();
    RunCheckpoint counting = RunCheckpoint::create(folder, config, options);
    counting.set_stop_requested([&total] { return ++total < 0; });
    options.journal = &counting;
    run_experiment(config, options);
    counting.remove();
  }
  ASSERT_GT(total, 20);
  for (const int stop_after : {1, 3, 4, 6, total / 2 + 1, total - 5, total}) {
    SCOPED_TRACE("stopped after save " + std::to_string(stop_after) + " of " + std::to_string(total));
    RunOptions options = two_seeds();
    {
      RunCheckpoint first = RunCheckpoint::create(folder, config, options);
      int saves = 0;
      first.set_stop_requested([&saves, stop_after] { return ++saves == stop_after; });
      options.journal = &first;
      EXPECT_THROW(run_experiment(config, options), RunInterrupted);
    }
    RunCheckpoint second = RunCheckpoint::resume(folder, config, options);
    options.journal = &second;
    const RunResults resumed = run_experiment(config, options);
    EXPECT_GT(second.restored_count(), 0);
    test::expect_same_results(resumed, reference);
    second.remove();
  }
  std::filesystem::remove_all(folder.parent_path());
}

TEST(RunResume, ACheckpointServesOnlyTheRunItWasMadeFor) {
  const auto dir = test::temporary_dir("run_resume_identity");
  const auto folder = dir / "r.h5.checkpoint";
  const RunConfig config = test::tiny_run_config();
  const auto message_of = [&](const RunConfig& c, const RunOptions& o) {
    try {
      RunCheckpoint::resume(folder, c, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message_of(config, two_seeds()).find("no checkpoint to resume from"), std::string::npos);
  RunCheckpoint::create(folder, config, two_seeds());
  try {
    RunCheckpoint::create(folder, config, two_seeds());
    ADD_FAILURE() << "a second create over an existing checkpoint must fail";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(RunCheckpoint::resume(folder, config, two_seeds()));
  RunOptions other_seeds = two_seeds();
  other_seeds.seeds = {3};
  EXPECT_NE(message_of(config, other_seeds).find("seeds 3,4, this run asks for 3"), std::string::npos)
      << message_of(config, other_seeds);
  RunOptions other_backends = two_seeds();
  other_backends.backends = {"exact", "fitc"};
  EXPECT_NE(message_of(config, other_backends).find("backends"), std::string::npos);
  RunConfig more_iterations = config;
  more_iterations.iterations = 5;
  EXPECT_NE(message_of(more_iterations, two_seeds()).find("iterations 2, this run asks for 5"), std::string::npos);
  const RunConfig other_config = parse_run_config("cartpole", std::string(test::kTinyRun) + "[control]\nu_max = [9.0]\n", "t.toml");
  EXPECT_NE(message_of(other_config, two_seeds()).find("a different config"), std::string::npos);

  // While a checkpoint is open (its lock held, in this process too), neither a second start nor a
  // resume may work in it; when it is removed, or its holder goes, the folder is free again.
  {
    const RunCheckpoint working = RunCheckpoint::resume(folder, config, two_seeds());
    const std::string in_use = fmt::format("in use by pid {}", ::getpid());
    EXPECT_NE(message_of(config, two_seeds()).find(in_use), std::string::npos) << message_of(config, two_seeds());
    try {
      RunCheckpoint::create(folder, config, two_seeds());
      ADD_FAILURE() << "a second start in a checkpoint in use";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(in_use), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(RunCheckpoint::resume(folder, config, two_seeds()));
  RunCheckpoint::resume(folder, config, two_seeds()).remove();
  EXPECT_FALSE(std::filesystem::exists(folder));
  EXPECT_NO_THROW(RunCheckpoint::create(folder, config, two_seeds()));
  std::filesystem::remove_all(dir);
}

// The same config text naming a model file that was edited in between: two simulators in one run.
TEST(RunResume, AModelFileTheConfigNamesThatWasEditedSinceIsRefused) {
  const auto dir = test::temporary_dir("run_resume_model_file");
  const auto folder = dir / "r.h5.checkpoint";
  const auto model = test::write_text(dir / "sm.toml", "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n");
  const auto config_file = test::write_text(dir / "c.toml", std::string(test::kTinyRun) + "[system]\nmodel = \"sm.toml\"\n");
  const RunConfig config = load_run_config("cartpole", config_file);
  ASSERT_EQ(config.files.size(), 1u);
  EXPECT_EQ(config.files[0].name, "the config's system.model");
  EXPECT_NE(config.files_text.find("preset = \"sim\""), std::string::npos) << config.files_text;
  RunCheckpoint::create(folder, config, two_seeds());
  EXPECT_NO_THROW(RunCheckpoint::resume(folder, load_run_config("cartpole", config_file), two_seeds()));
  test::write_text(model, "[model]\nsystem = \"cartpole\"\npreset = \"sim\"\n[parameters]\npole_length = 0.6\n");
  const RunConfig edited = load_run_config("cartpole", config_file);
  EXPECT_EQ(edited.text, config.text);
  try {
    RunCheckpoint::resume(folder, edited, two_seeds());
    ADD_FAILURE() << "a checkpoint resumed with an edited model file";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("other texts of the files its config names"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// A MuJoCo model's included files and assets are part of the run too: a --resume after the file the
// model includes was edited is refused; an asset (a mesh) is kept by its size and FNV-1a hash.
TEST(RunResume, AFileTheMujocoModelIncludesThatWasEditedSinceIsRefused) {
  const auto dir = test::temporary_dir("run_resume_included_file");
  const auto folder = dir / "r.h5.checkpoint";
  std::string arm = read_file_bytes(test::source_dir() / "data" / "two_link_arm.xml");
  const std::size_t begin = arm.find("<actuator>"), end = arm.find("</actuator>") + std::string("</actuator>").size();
  ASSERT_NE(begin, std::string::npos);
  const std::string motors = arm.substr(begin, end - begin);
  arm.replace(begin, end - begin, "<include file=\"motors.xml\"/>");
  test::write_text(dir / "arm.xml", arm);
  const auto included = test::write_text(dir / "motors.xml", "<mujoco>\n" + motors + "\n</mujoco>\n");
  std::string run = read_file_bytes(test::source_dir() / "data" / "two_link_arm_run.toml");
  run.replace(run.find("name = \"two_link_arm.xml\""), std::string("name = \"two_link_arm.xml\"").size(), "name = \"arm.xml\"");
  const auto config_file = test::write_text(dir / "c.toml", run);
  const std::string system = (dir / "arm.xml").string();
  const RunConfig config = load_run_config(system, config_file);
  ASSERT_EQ(config.files.size(), 2u);
  EXPECT_EQ(config.files[1].name, "the config's system.name's included MJCF file");
  EXPECT_NE(config.files_text.find("# the config's system.name's included MJCF file = " + included.string() + "\n<mujoco>"),
            std::string::npos)
      << config.files_text;
  RunCheckpoint::create(folder, config, two_seeds());
  EXPECT_NO_THROW(RunCheckpoint::resume(folder, load_run_config(system, config_file), two_seeds()));
  std::string geared = motors;
  geared.replace(geared.find("gear=\"1\""), 8, "gear=\"2\"");
  test::write_text(included, "<mujoco>\n" + geared + "\n</mujoco>\n");
  try {
    RunCheckpoint::resume(folder, load_run_config(system, config_file), two_seeds());
    ADD_FAILURE() << "a checkpoint resumed with an edited included file";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("other texts of the files its config names"), std::string::npos) << e.what();
  }
  // An asset by its size and hash: "a" is FNV-1a 64's published test vector.
  const auto mesh = test::write_text(dir / "a.stl", "a");
  EXPECT_EQ(config_files_text({{"the config's system.name's mesh file", mesh}}),
            "# the config's system.name's mesh file = " + mesh.string() + "\n1 bytes, FNV-1a 64 hash af63dc4c8601ec8c\n");
  std::filesystem::remove_all(dir);
}

/// A journal that hands a checkpoint every run with its first solve diverged: cost and gradient norm
/// not finite, as DdpSolver reports a backward pass that met a NaN.
class DivergedSolves : public RunJournal {
 public:
  explicit DivergedSolves(RunCheckpoint& checkpoint) : checkpoint_(checkpoint) {}
  std::optional<AlgorithmRun> restore(const TaskContext& context, std::uint64_t seed, const std::string& name) const override {
    return checkpoint_.restore(context, seed, name);
  }
  void save(const TaskContext& context, std::uint64_t seed, const AlgorithmRun& run) override {
    AlgorithmRun diverged = run;
    IterationRecord& first = diverged.iterations.front();
    first.plan.summary.final_gradient_norm = std::numeric_limits<double>::infinity();
    first.plan.summary.final_cost = std::numeric_limits<double>::infinity();
    first.plan.predicted_cost = std::numeric_limits<double>::infinity();
    checkpoint_.save(context, seed, diverged);
    ++saves;
    const std::optional<AlgorithmRun> back = checkpoint_.restore(context, seed, run.name);
    restored_infinite = restored_infinite && back && std::isinf(back->iterations.front().plan.summary.final_gradient_norm) &&
                        std::isinf(back->iterations.front().plan.summary.final_cost) &&
                        std::isinf(back->iterations.front().plan.predicted_cost);
  }
  int saves = 0;
  bool restored_infinite = true;

 private:
  RunCheckpoint& checkpoint_;
};

// Every number of a checkpoint file is finite: a diverged solve's cost and gradient norm are left out
// and read back as not finite.
TEST(RunResume, ACheckpointHoldsFiniteNumbersOnlyAndReadsADivergedSolveBack) {
  const RunConfig config = test::tiny_run_config();
  const auto folder = test::temporary_dir("run_resume_finite") / "run.h5.checkpoint";
  RunOptions options;
  options.seeds = {3};
  RunCheckpoint checkpoint = RunCheckpoint::create(folder, config, options);
  DivergedSolves journal(checkpoint);
  options.journal = &journal;
  run_experiment(config, options);
  ASSERT_GT(journal.saves, 0);
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder))
    if (entry.path().extension() == ".h5" && entry.path().filename() != "manifest.h5") {  // attributes only
      ++files;
      EXPECT_TRUE(test::hdf5_datasets_finite(entry.path())) << entry.path();
    }
  EXPECT_GT(files, 0);
  EXPECT_TRUE(journal.restored_infinite);
  checkpoint.remove();
  std::filesystem::remove_all(folder.parent_path());
}

TEST(RunResume, ADamagedManifestIsReportedAsADamagedCheckpointWithTheWayToStartOver) {
  const auto dir = test::temporary_dir("run_resume_damaged");
  const auto folder = dir / "r.h5.checkpoint";
  const RunConfig config = test::tiny_run_config();
  RunCheckpoint::create(folder, config, two_seeds());
  const auto manifest = folder / "manifest.h5";
  const std::string whole = read_file_bytes(manifest);
  const std::vector<std::pair<std::string, std::string>> damages = {
      {"truncated", whole.substr(0, whole.size() / 2)}, {"garbage", std::string(4096, '\x5a')}, {"empty", ""}};
  for (const auto& [name, bytes] : damages) {
    SCOPED_TRACE(name);
    std::ofstream(manifest, std::ios::binary | std::ios::trunc) << bytes;
    try {
      RunCheckpoint::resume(folder, config, two_seeds());
      ADD_FAILURE() << "a damaged manifest was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(manifest.string() + ": the checkpoint is damaged, its manifest cannot be read (", 0), 0u) << what;
      EXPECT_NE(what.find("); delete the folder " + folder.string() + " to start the run over"), std::string::npos) << what;
    }
  }
  std::filesystem::remove_all(dir);
}

// ---- the real program, with real signals -------------------------------------------------------

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

/// Starts `gpilqg run cartpole --config CONFIG --out OUT --no-plots`, output to LOG.
pid_t start_run(const std::filesystem::path& config, const std::filesystem::path& out, const std::filesystem::path& log) {
  const std::string program = test::program_path();
  const std::string config_s = config.string(), out_s = out.string();
  std::vector<std::string> args = {program, "run", "cartpole", "--config", config_s, "--out", out_s, "--no-plots"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error("cannot start " + program);
  return pid;
}

/// Waits until the checkpoint folder holds `files` entries (the manifest and the first saves; not the
/// lock file).
bool wait_for_checkpoint_files(const std::filesystem::path& folder, int files, pid_t child) {
  for (int i = 0; i < 120000; ++i) {
    int count = 0;
    std::error_code error;
    for (auto it = std::filesystem::directory_iterator(folder, error); !error && it != std::filesystem::directory_iterator(); ++it)
      count += is_atomic_temporary(it->path()) || it->path().filename() == "lock" ? 0 : 1;
    if (count >= files) return true;
    if (waitpid(child, nullptr, WNOHANG) == child) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  return false;
}

class RunSignalsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temporary_dir("run_signals");
    // Three data rounds on 25-step tasks: long enough that the signal lands mid-run.
    std::string text = test::kTinyRun;
    text.replace(text.find("iterations = 2"), 14, "iterations = 3");
    for (std::size_t at = text.find("horizon = 15"); at != std::string::npos; at = text.find("horizon = 15"))
      text.replace(at, 12, "horizon = 25");
    config_ = dir_ / "signals.toml";
    std::ofstream(config_) << text;
    reference_ = dir_ / "reference.h5";
    const auto done = test::run_cli("run cartpole --config '" + config_.string() + "' --out '" + reference_.string() + "' --no-plots");
    ASSERT_EQ(done.status, 0) << done.err;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Resumes the interrupted run of `out` and checks it against the uninterrupted reference.
  void resume_and_compare(const std::filesystem::path& out) {
    const auto resumed = test::run_cli("run cartpole --config '" + config_.string() + "' --out '" + out.string() +
                                       "' --no-plots --resume");
    ASSERT_EQ(resumed.status, 0) << resumed.err;
    EXPECT_NE(resumed.err.find("resumed after iteration"), std::string::npos) << resumed.err;
    EXPECT_FALSE(std::filesystem::exists(RunCheckpoint::folder_for(out))) << "the checkpoint outlived the finished run";
    test::expect_same_result_files(out, reference_);
  }

  std::filesystem::path dir_, config_, reference_;
};

TEST_F(RunSignalsCli, SigintStopsAtAnIterationLeavesThePreviousResultAndResumesToTheSameResult) {
  const auto out = dir_ / "result.h5";
  const std::string previous = "a previous result that must survive";
  std::ofstream(out, std::ios::binary) << previous;
  const pid_t child = start_run(config_, out, dir_ / "interrupted.log");
  ASSERT_TRUE(wait_for_checkpoint_files(RunCheckpoint::folder_for(out), 2, child)) << "the run ended before its first save";
  ASSERT_EQ(kill(child, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  const std::string log = read_bytes(dir_ / "interrupted.log");
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 130) << log;
  EXPECT_NE(log.find("interrupted: stopped after"), std::string::npos) << log;
  EXPECT_NE(log.find("--resume"), std::string::npos) << log;
  EXPECT_EQ(read_bytes(out), previous);
  for (const auto& entry : std::filesystem::directory_iterator(dir_))
    EXPECT_FALSE(is_atomic_temporary(entry.path())) << "left behind: " << entry.path();
  resume_and_compare(out);
}

// One run at a time on a result file: while a run works, a second run on the same --out and a --resume
// of it are refused at once, naming the run's pid, and the run finishes with the uninterrupted result.
TEST_F(RunSignalsCli, ASecondRunOrAResumeWhileARunWorksIsRefusedAndTheRunFinishes) {
  const auto out = dir_ / "busy.h5";
  const pid_t child = start_run(config_, out, dir_ / "busy.log");
  ASSERT_TRUE(wait_for_checkpoint_files(RunCheckpoint::folder_for(out), 2, child)) << "the run ended before its first save";
  const std::string run = "run cartpole --config '" + config_.string() + "' --out '" + out.string() + "' --no-plots";
  const std::string in_use = fmt::format("in use by pid {}", child);
  for (const std::string& second : {run, run + " --resume"}) {
    const auto refused = test::run_cli(second);
    EXPECT_EQ(refused.status, 2) << second << "\n" << refused.err;
    EXPECT_NE(refused.err.find(in_use), std::string::npos) << second << "\n" << refused.err;
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  const std::string log = read_bytes(dir_ / "busy.log");
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 0) << log;
  EXPECT_FALSE(std::filesystem::exists(RunCheckpoint::folder_for(out)));
  test::expect_same_result_files(out, reference_);
}

TEST_F(RunSignalsCli, SigkillAtAnyMomentLeavesACheckpointThatResumesToTheSameResult) {
  // No chance to stop cleanly: whatever the moment, each checkpoint file is the old or the new one.
  const auto out = dir_ / "killed.h5";
  const pid_t child = start_run(config_, out, dir_ / "killed.log");
  ASSERT_TRUE(wait_for_checkpoint_files(RunCheckpoint::folder_for(out), 4, child)) << "the run ended before its third save";
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_FALSE(std::filesystem::exists(out));
  resume_and_compare(out);
}

}  // namespace
}  // namespace gpilqg
