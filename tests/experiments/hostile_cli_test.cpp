/// A careful user's worst day, end to end through the `gpilqg` program: a full disk under every
/// writer, output paths that cannot be written, absurd sizes and option values. Each case names
/// what it gets (docs/reliability.md): a full disk is exit 1 with the path and the OS error and the
/// previous file byte for byte; everything else is exit 2 naming the option or field, before any
/// computation.

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> listing(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

/// The inputs every writer below reads: a measurement file, a run and a plan config, a policy file,
/// two run results of one seed each.
struct Inputs {
  fs::path data, run_config, plan_config, policy, seed_1, seed_2, sweep;
};

Inputs make_inputs(const fs::path& dir) {
  Inputs in{dir / "data.csv", test::write_text(dir / "run.toml", test::kTinyRun), test::write_text(dir / "plan.toml", test::kTinyPlan),
            dir / "policy.h5", dir / "seed_1.h5", dir / "seed_2.h5",
            test::write_text(dir / "sweep.toml", "system = \"cartpole\"\nconfig = \"run.toml\"\n[grid]\n\"loop.rollouts\" = [1, 2]\n")};
  EXPECT_EQ(test::run_cli("simulate --system cartpole --episodes 4 --steps 60 --out " + test::quote(in.data)).status, 0);
  EXPECT_EQ(test::run_cli("plan " + test::quote(in.plan_config) + " --out " + test::quote(in.policy)).status, 0);
  for (const auto& [seed, part] : {std::pair{"1", in.seed_1}, std::pair{"2", in.seed_2}})
    EXPECT_EQ(test::run_cli("run cartpole --config " + test::quote(in.run_config) + " --first-seed " + seed + " --no-plots --out " +
                            test::quote(part))
                  .status,
              0);
  return in;
}

/// Every command that writes a result file, as "command with {out}" and the file's name.
struct Writer {
  std::string name;
  std::string command;  ///< "{out}" stands for the output path
  std::string file;
};

std::vector<Writer> writers(const Inputs& in) {
  return {
      {"simulate to HDF5", "simulate --system cartpole --episodes 4 --steps 200 --out {out}", "data.h5"},
      {"simulate to CSV", "simulate --system cartpole --episodes 4 --steps 200 --out {out}", "data.csv"},
      {"diagnose --out", "diagnose --system cartpole --data " + test::quote(in.data) + " --gp-restarts 0 --out {out}", "report.h5"},
      {"diagnose --write-model", "diagnose --system cartpole --data " + test::quote(in.data) + " --gp-restarts 0 --write-model {out}",
       "model.toml"},
      {"profile --out", "profile " + test::quote(in.data) + " --system cartpole --backends exact --sizes 60 --out {out}", "profile.h5"},
      {"run --out", "run cartpole --config " + test::quote(in.run_config) + " --no-plots --out {out}", "run.h5"},
      {"sweep --out", "sweep " + test::quote(in.sweep) + " --no-plots --out {out}", "sweep.h5"},
      {"merge --out", "merge " + test::quote(in.seed_1) + " " + test::quote(in.seed_2) + " --no-plots --out {out}", "merged.h5"},
      {"plan --out", "plan " + test::quote(in.plan_config) + " --out {out}", "policy.h5"},
      {"rollout --out", "rollout --system cartpole --policy " + test::quote(in.policy) + " --out {out}", "log.csv"},
  };
}

std::string with_out(std::string command, const fs::path& out) {
  command.replace(command.find("{out}"), 5, test::quote(out));
  return command;
}

/// A small tmpfs mounted for the test and filled to the last byte; unmounted at the end.
class FullDisk {
 public:
  explicit FullDisk(const fs::path& mount_point) : mount_point_(mount_point) {
    fs::create_directories(mount_point_);
    mounted_ = ::mount("tmpfs", mount_point_.c_str(), "tmpfs", 0, "size=1m") == 0;
    if (!mounted_) reason_ = std::strerror(errno);
  }
  ~FullDisk() {
    if (mounted_) ::umount2(mount_point_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }
  const std::string& reason() const { return reason_; }
  /// Writes a filler file until the file system refuses (ENOSPC).
  void fill() const {
    std::ofstream filler(mount_point_ / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    while (filler.write(block.data(), static_cast<std::streamsize>(block.size()))) filler.flush();
  }
  /// Removes every file.
  void empty() const {
    for (const auto& entry : fs::directory_iterator(mount_point_)) fs::remove_all(entry.path());
  }

 private:
  fs::path mount_point_;
  bool mounted_ = false;
  std::string reason_;
};

TEST(HostileCli, AFullDiskUnderEveryWriterIsExit1AndKeepsThePreviousFile) {
  const fs::path dir = test::temporary_dir("hostile_disk");
  const Inputs in = make_inputs(dir);
  const FullDisk disk(dir / "disk");
  if (!disk.mounted())
    GTEST_SKIP() << "cannot mount a small tmpfs here (" << disk.reason() << "; needs root or CAP_SYS_ADMIN)";
  for (const Writer& w : writers(in)) {
    SCOPED_TRACE(w.name);
    disk.empty();
    const fs::path out = dir / "disk" / w.file;
    const std::string previous = "the previous result of " + w.name + "\n";
    test::write_text(out, previous);
    disk.fill();
    const auto r = test::run_cli(with_out(w.command, out));
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(out.string()), std::string::npos) << "the message names the file: " << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_text(out), previous);
    std::vector<std::string> expected{"filler", w.file};
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(listing(dir / "disk"), expected) << "no temporary or checkpoint left";
  }
}

TEST(HostileCli, OutputPathsThatCannotBeWrittenAreExit2BeforeAnyWork) {
  const fs::path dir = test::temporary_dir("hostile_paths");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  fs::create_directory(dir / "folder");
  test::write_text(dir / "a_file", "x");
  struct Case {
    std::string arguments, message;
  };
  const std::string simulate = "simulate --system cartpole --episodes 1 --steps 20 ";
  const std::vector<Case> cases = {
      {simulate + "--out /dev/null", "--out /dev/null: is a character device; expected a regular file or a new file name"},
      {simulate + "--out " + test::quote(dir / "fifo"), "is a FIFO (named pipe); expected a regular file or a new file name"},
      {simulate + "--out " + test::quote(dir / "folder"), "is a folder; expected a regular file or a new file name"},
      {simulate + "--out " + test::quote(dir / "a_file" / "x.csv"), "a_file is a regular file; expected a folder"},
      {"run cartpole --plots " + test::quote(dir / "a_file"), "--plots " + (dir / "a_file").string() + ": is a regular file; expected a folder"},
      {simulate + "--out " + test::quote(dir / (std::string(256, 'n') + ".csv")), "the file name has 260 bytes; expected at most 255"},
  };
  for (const Case& c : cases) {
    const auto r = test::run_cli(c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.arguments << "\n" << r.err;
  }
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  EXPECT_TRUE(fs::is_fifo(dir / "fifo"));
}

TEST(HostileCli, ALongLegalFileNameIsWrittenAndTemporariesOfDeadProcessesAreRemoved) {
  const fs::path dir = test::temporary_dir("hostile_names");
  const fs::path out = dir / (std::string(250, 'n') + ".csv");  // 254 bytes: legal, its temporary name is shortened
  const std::string simulate = "simulate --system cartpole --episodes 1 --steps 20 --out " + test::quote(out);
  // A temporary left by a process that no longer runs (a child that has exited) beside the target.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  std::string name = atomic_temporary_path(out).filename().string();
  name = name.substr(0, name.rfind(".tmp-") + 5) + std::to_string(child) + "-0";
  const fs::path leftover = dir / name;
  test::write_text(leftover, "half a file");
  const auto r = test::run_cli(simulate);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(out));
  EXPECT_NE(r.err.find("note: removed " + leftover.string() + ", a temporary file left by an interrupted write"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(listing(dir), (std::vector<std::string>{out.filename().string()}));
}

TEST(HostileCli, AbsurdSizesAndOptionValuesAreExit2NamingTheLimit) {
  const fs::path dir = test::temporary_dir("hostile_sizes");
  const std::string tasks = R"(
[[tasks]]
name = "long"
x0 = [0.0, 0.0, 0.3, 0.0]
goal = [0.0, 0.0, 0.0, 0.0]
horizon = HORIZON
Q = [1.0, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
track_line = false
transfer = false
)";
  auto config_with_horizon = [&](const std::string& horizon, const std::string& name) {
    std::string text = tasks;
    text.replace(text.find("HORIZON"), 7, horizon);
    return test::quote(test::write_text(dir / name, text));
  };
  struct Case {
    std::string arguments, message;
  };
  const std::string out = " --out " + test::quote(dir / "out.csv");
  const std::vector<Case> cases = {
      {"run cartpole --config " + config_with_horizon("1000000000", "h1e9.toml"),
       "field 'tasks[0].horizon': is 1000000000; expected an integer from 2 to 1000000"},
      {"run cartpole --config " + config_with_horizon("1000000", "h1e6.toml"),
       "field 'tasks[0].horizon': 1000000 steps of 4 (belief-space) states and 1 controls need about"},
      {"run cartpole --iterations 1000000000", "--iterations: is 1000000000; expected a whole number from 1 to 1000"},
      {"run cartpole --iterations -3", "--iterations: is -3; expected a whole number from 1 to 1000"},
      {"run cartpole --iterations 1e9", "--iterations: '1e9' is not a whole number"},
      {"run cartpole --first-seed -1", "--first-seed: is -1; expected a whole number from 0 to 9007199254740992"},
      {"run cartpole --seeds 1000000", "--seeds: is 1000000; expected a whole number from 1 to 1000"},
      {"diagnose --system cartpole --data x.csv --gp-restarts 1000000000", "--gp-restarts: is 1000000000; expected a whole number from 0 to 1000"},
      {"profile x.h5 --backends ssgp --frequencies 100000000", "--frequencies: is 100000000; expected a whole number from 1 to 4096"},
      {"profile x.h5 --backends fitc --inducing 1000000", "--inducing: is 1000000; expected a whole number from 1 to 10000"},
      {"profile x.h5 --backends exact --test-every 0", "--test-every: is 0; expected a whole number from 2 to 10000000"},
      {"simulate --system cartpole --episodes 1000000 --steps 1000000" + out, "--episodes: is 1000000; expected a whole number from 1 to 100000"},
      {"simulate --system cartpole --episodes 100000 --steps 1000" + out,
       "--episodes 100000 x --steps 1000: 100000000 samples; expected at most 10000000 (the sample limit)"},
      {"simulate --system cartpole --dt 0" + out, "--dt: is 0; expected a finite number > 0"},
      {"simulate --system cartpole --dt nan" + out, "--dt: is nan; expected a finite number > 0"},
      {"simulate --system cartpole --episodes -1" + out, "--episodes: is -1; expected a whole number from 1 to 100000"},
      {"simulate --system cartpole --observation-noise -1" + out, "--observation-noise: is -1; expected a finite number >= 0"},
      {"simulate --system cartpole --param pole_length=inf" + out, "--param 'pole_length=inf': the value is not a finite number"},
      {"rollout --system cartpole --policy p.h5 --x0 1e300,0,0,0" + out, "--x0: is 1e300; expected a finite number >= -1000000000000 and <= 1000000000000"},
      {"frobnicate", "error: unknown command 'frobnicate'; expected one of: data, solve, simulate, diagnose, run, sweep, merge, profile, plan, rollout"},
  };
  for (const Case& c : cases) {
    const auto r = test::run_cli(c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.arguments << "\n" << r.err;
    EXPECT_LT(r.err.size(), 2000u) << c.arguments;
  }
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

TEST(HostileCli, TooManySeedsLeaveNoCheckpointAndAnEmptyCheckpointDoesNotBlockANewRun) {
  const fs::path dir = test::temporary_dir("hostile_checkpoint");
  const fs::path out = dir / "run.h5";
  const auto refused = test::run_cli("run cartpole --seeds 1000000 --no-plots --out " + test::quote(out));
  EXPECT_EQ(refused.status, 2) << refused.err;
  EXPECT_EQ(listing(dir), std::vector<std::string>{});
  // A checkpoint folder whose manifest was never written (a start killed at the wrong moment).
  fs::create_directory(dir / "run.h5.checkpoint");
  const auto run = test::run_cli("run cartpole --config " + test::quote(test::write_text(dir / "tiny.toml", test::kTinyRun)) +
                                 " --no-plots --out " + test::quote(out));
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_EQ(listing(dir), (std::vector<std::string>{"run.h5", "tiny.toml"}));
}

}  // namespace
}  // namespace gpilqg
