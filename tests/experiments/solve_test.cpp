// `gpilqg solve`: the reference optima through the real binary (JSON output), and a table of bad
// configs, each with its own clear error naming the file, line and field.

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "finite_checks.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

std::string config_path(const char* name) { return (test::source_dir() / "experiments" / "configs" / name).string(); }

TEST(SolveCommandCli, ReachesTheReferenceOptimaFromTheCommandLine) {
  struct Case { const char* file; double cost; double x_final_theta; };
  // tests/reference/ilqr_cartpole: summary.csv, cases C and E.
  for (const Case c : {Case{"cartpole_swingup.toml", 0.645046921446, 3.14042815352604},
                       Case{"cartpole_swingup_box.toml", 0.677802315918, 3.14039027}}) {
    const auto r = test::run_cli("solve '" + config_path(c.file) + "' --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j["cost"].get<double>(), c.cost, 1e-8 * c.cost) << c.file;
    EXPECT_NEAR(j["x_final"][2].get<double>(), c.x_final_theta, 1e-5) << c.file;
    EXPECT_EQ(j["u"].size(), 100u);
    for (const char* key : {"iterations", "termination", "solve_time_s"}) EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
}

TEST(SolveCommandCli, IlqgExampleReportsTheExpectedCostAboveTheNominal) {
  const auto r = test::run_cli("solve '" + config_path("cartpole_swingup_ilqg.toml") + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["algorithm"], "ilqg");
  EXPECT_GT(j["expected_cost"].get<double>(), j["cost"].get<double>());
}

struct BadConfig {
  const char* name;
  const char* edit_from;  // text of the reference config to replace...
  const char* edit_to;    // ... with this
  const char* expected;   // substring of the error
};

void PrintTo(const BadConfig& c, std::ostream* os) { *os << c.name; }

class SolveBadConfigCli : public ::testing::TestWithParam<BadConfig> {};

TEST_P(SolveBadConfigCli, ExitsTwoWithAClearError) {
  const BadConfig c = GetParam();
  std::ifstream in(config_path("cartpole_swingup.toml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(c.edit_from);
  ASSERT_NE(at, std::string::npos) << c.edit_from;
  text.replace(at, std::string(c.edit_from).size(), c.edit_to);
  const auto file = test::temporary_dir("solve") / "bad.toml";
  std::ofstream(file) << text;
  const auto r = test::run_cli("solve '" + file.string() + "'");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("bad.toml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    Table, SolveBadConfigCli,
    ::testing::Values(
        BadConfig{"syntax", "horizon = 100", "horizon = = 100", "bad.toml:line 9: "},
        BadConfig{"unknown_field", "horizon = 100", "horizon = 100\nhorizn = 5", "unknown field 'problem.horizn'"},
        BadConfig{"unknown_system", "name = \"cartpole\"", "name = \"pendulum\"", "unknown system 'pendulum'"},
        BadConfig{"wrong_size", "x0 = [0, 0, 0, 0]", "x0 = [0, 0, 0]", "field 'problem.x0': has 3 entries; expected 4"},
        BadConfig{"not_a_number", "R = [0.1]", "R = [\"a\"]", "field 'problem.R': entry 0 is not a number"},
        BadConfig{"negative_weight", "R = [0.1]", "R = [-0.1]", "field 'problem.R': has negative entries"},
        // A weight of 1e308 makes the cost of a state of 10 overflow, which the solver would take for divergence.
        BadConfig{"huge_weight", "Qf = [100, 100, 1000, 100]", "Qf = [1e308, 100, 1000, 100]",
                  "field 'problem.Qf': entry 0 is 1e+308; expected a weight in [0, 1e+150] (a larger one makes the cost "
                  "of states within the divergence bound overflow)"},
        BadConfig{"bad_algorithm", "algorithm = \"ilqr\"", "algorithm = \"ddp\"", "field 'solver.algorithm'"},
        BadConfig{"bad_integrator", "integrator = \"euler\"", "integrator = \"rk45\"", "field 'system.integrator'"},
        BadConfig{"zero_dt", "dt = 0.05", "dt = 0", "field 'system.dt': must be > 0"},
        BadConfig{"missing_section", "[problem]", "[problm]", "unknown field 'problm'"},
        BadConfig{"missing_field", "Qf = [100, 100, 1000, 100]", "", "field 'problem.Qf': missing"},
        BadConfig{"limits_crossed", "Qf = [100, 100, 1000, 100]", "Qf = [100, 100, 1000, 100]\nu_min = [3]\nu_max = [2]",
                  "field 'problem.u_min': exceeds problem.u_max"},
        BadConfig{"bad_solver_option", "max_iterations = 1000", "max_iterations = 0", "max_iterations"},
        // Integers beyond an int were once cut to it: 4294967297 became a horizon of 1.
        BadConfig{"horizon_beyond_int", "horizon = 100", "horizon = 4294967297",
                  "field 'problem.horizon': is 4294967297; expected an integer from 1 to 1000000"},
        BadConfig{"huge_iterations", "max_iterations = 1000", "max_iterations = 9223372036854775807",
                  "field 'solver.max_iterations': is 9223372036854775807; expected an integer from 1 to"},
        // A start or goal beyond the divergence bound would only be found to diverge (or overflow).
        BadConfig{"x0_beyond_bound", "x0 = [0, 0, 0, 0]", "x0 = [1e300, 0, 0, 0]",
                  "bad.toml:line 10: field 'problem.x0': entry 0 is 1e+300; expected |value| <= 1e+12 (beyond it a "
                  "state counts as diverged)"},
        BadConfig{"goal_beyond_bound", "goal = [0, 0, 3.141592653589793, 0]", "goal = [0, 0, -1e13, 0]",
                  "field 'problem.goal': entry 2 is -1e+13; expected |value| <= 1e+12"},
        BadConfig{"u_init_beyond_bound", "R = [0.1]", "R = [0.1]\nu_init = [1e300]",
                  "field 'problem.u_init': entry 0 is 1e+300; expected |value| <= 1e+12"},
        BadConfig{"huge_substeps", "dt = 0.05", "dt = 0.05\nsubsteps = -4294967295",
                  "field 'system.substeps': is -4294967295; expected an integer from 1 to 10000"}),
    [](const auto& info) { return std::string(info.param.name); });

/// The reference config with `edit_from` replaced by `edit_to`, written to a temporary file.
std::string edited_config(const std::string& edit_from, const std::string& edit_to) {
  std::ifstream in(config_path("cartpole_swingup.toml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find(edit_from), edit_from.size(), edit_to);
  const auto file = test::temporary_dir("solve_status") / "problem.toml";
  std::ofstream(file) << text;
  return "'" + file.string() + "'";
}

TEST(SolveCommandCli, ATooLongStepStallsAndIsNotReportedConverged) {
  // Euler steps of 1 s: once "converged" (cost_change) with a gradient norm of 8e53.
  const std::string file = edited_config("dt = 0.05", "dt = 1");
  const auto text = test::run_cli("solve " + file);
  EXPECT_EQ(text.status, 1) << text.out;
  EXPECT_EQ(text.out.rfind("ilqr: stalled after ", 0), 0u) << text.out;
  EXPECT_NE(text.err.find("warning: not converged: the cost stopped changing but the gradient |g| = "), std::string::npos)
      << text.err;
  const auto r = test::run_cli("solve " + file + " --json");
  EXPECT_EQ(r.status, 1);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["termination"], "stalled");
  EXPECT_FALSE(j["converged"].get<bool>());
  EXPECT_TRUE(test::json_numbers_finite(j));
}

TEST(SolveCommandCli, InitialControlsThatDivergeAreAStatusWithAFiniteCost) {
  // Within the bound of the config, but the first step already leaves |x| <= 1e12.
  const std::string file = edited_config("R = [0.1]", "R = [0.1]\nu_init = [1e12]");
  const auto r = test::run_cli("solve " + file + " --json");
  EXPECT_EQ(r.status, 1) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["termination"], "initial_rollout_diverged");
  EXPECT_FALSE(j["converged"].get<bool>());
  ASSERT_TRUE(j["cost"].is_number()) << r.out.substr(0, 300);  // the cost of the states reached, not null
  EXPECT_GT(j["cost"].get<double>(), 1e20);
  EXPECT_TRUE(test::json_numbers_finite(j));
  EXPECT_NE(r.err.find("warning: not converged: the initial controls drive the model beyond"), std::string::npos) << r.err;
  const auto text = test::run_cli("solve " + file);
  for (const char* word : {"inf", "nan"}) EXPECT_EQ(text.out.find(word), std::string::npos) << text.out;
}

TEST(SolveCommandCli, AMissingFileIsBadInput) {
  const auto r = test::run_cli("solve /nonexistent/problem.toml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/nonexistent/problem.toml: no such file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gpilqg
