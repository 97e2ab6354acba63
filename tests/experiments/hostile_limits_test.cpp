/// Hostile values that no size limit covers: names the result file cannot hold, names that JSON
/// cannot hold, options and config fields beyond the divergence bound, and worlds that diverge at
/// once. Each is bad input named by its field or option (exit 2), or, where the run itself
/// diverges, a reported outcome (exit 1), never an internal error.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "gpilqg/core/utf8.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/run_config.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

using test::quote;

/// The tiny run config with its first task's name line replaced.
std::string with_first_task_name(const std::string& name_line) {
  std::string text = test::kTinyRun;
  const std::string first = "name = \"first\"";
  text.replace(text.find(first), first.size(), name_line);
  return text;
}

std::string run_config_error(const std::string& text) {
  try {
    parse_run_config("cartpole", text, "t.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(HostileLimits, TaskNamesTheResultFileCannotHoldAreRefusedNamingTheField) {
  const std::string rule = "expected a non-empty name without '/', whitespace or control characters, not '.', '..' or "
                           "'seeds' (it names the task's HDF5 group /<name> in the result file)";
  struct Case {
    std::string name_line, problem;
  };
  const std::vector<Case> cases = {
      {"name = \".\"", "'.' is reserved by the result file's layout"},
      {"name = \"..\"", "'..' is reserved by the result file's layout"},
      {"name = \"seeds\"", "'seeds' is reserved by the result file's layout"},
      {"name = \"\"", "is empty"},
      {"name = \"a/b\"", "'a/b' holds '/'"},
      {"name = \"a b\"", "'a b' holds whitespace or a control character"},
      {"name = \"a\\tb\"", "'a\\x09b' holds whitespace or a control character"},
  };
  for (const Case& c : cases) {
    const std::string e = run_config_error(with_first_task_name(c.name_line));
    EXPECT_NE(e.find("t.toml:line 20: field 'tasks[0].name': " + c.problem + "; " + rule), std::string::npos)
        << c.name_line << "\n" << e;
  }
  EXPECT_EQ(run_config_error(with_first_task_name("name = \"seeds_2\"")), "no error");
  EXPECT_EQ(run_config_error(with_first_task_name("name = \"schwung_\u00fcber\"")), "no error");  // UTF-8 is fine
}

TEST(HostileLimits, Utf8IsCheckedByItsRulesAndShownEscaped) {
  EXPECT_TRUE(is_valid_utf8("plain"));
  EXPECT_TRUE(is_valid_utf8("\xc3\xbc\xe2\x82\xac\xf0\x9f\x98\x80"));  // u-umlaut, euro, an emoji
  for (const std::string bad : {"\xff", "a\xc3", "\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xe2\x82"})
    EXPECT_FALSE(is_valid_utf8(bad)) << escaped_bytes(bad);
  EXPECT_EQ(escaped_bytes("log\xff.csv"), "log\\xff.csv");
  EXPECT_EQ(escaped_bytes("a\\b"), "a\\x5cb");
}

TEST(HostileLimits, ALogColumnNameThatIsNotUtf8IsRefusedWhenTheLogIsRead) {
  const fs::path dir = test::temporary_dir("hostile_utf8_column");
  const fs::path log = dir / "log.csv";
  std::ofstream(log) << "t,x\xff\n0,1\n0.1,2\n";
  try {
    read_raw_log(log);
    ADD_FAILURE() << "a column name that is not UTF-8 was accepted";
  } catch (const DataError& e) {
    EXPECT_EQ(std::string(e.what()), log.string() + ":column 'x\\xff': the column's name is not valid UTF-8; expected "
                                                     "column names in UTF-8");
  }
  fs::remove_all(dir);
}

TEST(HostileLimitsCli, TheCommandLineNamesTheOptionOrReportsTheDivergence) {
  const fs::path dir = test::temporary_dir("hostile_limits_cli");
  const fs::path out = dir / "out.csv";
  // A measurement file whose name is not UTF-8: refused before it is read when --json is asked.
  const fs::path latin1 = dir / "m\xe9sures.csv";
  struct Case {
    std::string arguments;
    int status;
    std::string message;
  };
  std::vector<Case> cases = {
      {"simulate --system cartpole --observation-noise 1e308 --out " + quote(out), 2,
       "error: --observation-noise: is 1e308; expected a finite number >= 0 and <= 1000000000000"},
      {"simulate --system cartpole --dt 100000 --out " + quote(out), 2,
       "error: every simulated episode diverged before its second sample at --dt 100000 s; expected a shorter --dt"},
      {"data info " + quote(latin1) + " --system cartpole --json", 2,
       "error: FILE '" + (dir / "m\\xe9sures.csv").string() +
           "': is not valid UTF-8; expected UTF-8 names with --json (JSON output holds only UTF-8 text)"},
      // diagnose --out stores its report as a JSON attribute: the same rule.
      {"diagnose --system cartpole --data " + quote(latin1) + " --out " + quote(dir / "report.h5"), 2,
       "error: --data '" + (dir / "m\\xe9sures.csv").string() +
           "': is not valid UTF-8; expected UTF-8 names with --out (JSON output holds only UTF-8 text)"},
  };
  // A run whose sensor noise puts the measured states where the simulator diverges.
  std::string noisy = test::kTinyRun;
  const std::string observation = "observation = [0.001, 0.001, 0.001, 0.001]";
  noisy.replace(noisy.find(observation), observation.size(), "observation = [0.001, 0.001, 0.001, 1e11]");
  std::ofstream(dir / "noisy.toml") << noisy;
  cases.push_back({"run cartpole --config " + quote(dir / "noisy.toml") + " --no-plots --out " + quote(dir / "noisy.h5"),
                   2,
                   "error: field 'noise.observation' = [0.001, 0.001, 0.001, 1e+11]: the simulator's step is not finite "
                   "at 15 of 15 measured inputs"});
  // A policy whose every episode diverges at its first step: a reported outcome, exit 1 as for a
  // solve that does not converge; nothing written.
  std::ofstream(dir / "plan.toml") << test::kTinyPlan;
  const auto plan = test::run_cli("plan " + quote(dir / "plan.toml") + " --out " + quote(dir / "policy.h5"));
  ASSERT_EQ(plan.status, 0) << plan.err;
  const auto diverging = test::run_cli("rollout --system cartpole --policy " + quote(dir / "policy.h5") +
                                       " --x0 9e11,0,0,9e11 --episodes 2 --out " + quote(out));
  EXPECT_EQ(diverging.status, 1) << diverging.err;
  EXPECT_EQ(diverging.out, "2 of 2 episode(s) diverged at their first step: status diverged (a state not finite or "
                           "beyond |x| = 1e+12); " + out.string() + " not written\n");
  EXPECT_EQ(diverging.err, "warning: not written: every episode of the round-0 policy " + (dir / "policy.h5").string() +
                               " diverged at its first step, so " + out.string() +
                               " would hold no transition (try another --x0, world or policy)\n");
  for (const Case& c : cases) {
    const auto r = test::run_cli(c.arguments);
    EXPECT_EQ(r.status, c.status) << c.arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.arguments << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg
