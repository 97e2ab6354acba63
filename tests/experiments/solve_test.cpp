// `gpilqg solve`: the reference optima through the real binary (JSON output), and a table of bad
// configs, each with its own clear error naming the file, line and field.

#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace gpilqg {
namespace {

std::string config_path(const char* name) { return (test::source_dir() / "experiments" / "configs" / name).string(); }

TEST(SolveCommand, ReachesTheReferenceOptimaFromTheCommandLine) {
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

TEST(SolveCommand, IlqgExampleReportsTheExpectedCostAboveTheNominal) {
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

class SolveBadConfig : public ::testing::TestWithParam<BadConfig> {};

TEST_P(SolveBadConfig, ExitsTwoWithAClearError) {
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
    Table, SolveBadConfig,
    ::testing::Values(
        BadConfig{"syntax", "horizon = 100", "horizon = = 100", "bad.toml:line 9: "},
        BadConfig{"unknown_field", "horizon = 100", "horizon = 100\nhorizn = 5", "unknown field 'problem.horizn'"},
        BadConfig{"unknown_system", "name = \"cartpole\"", "name = \"pendulum\"", "unknown system 'pendulum'"},
        BadConfig{"wrong_size", "x0 = [0, 0, 0, 0]", "x0 = [0, 0, 0]", "field 'problem.x0': has 3 entries; expected 4"},
        BadConfig{"not_a_number", "R = [0.1]", "R = [\"a\"]", "field 'problem.R': entry 0 is not a number"},
        BadConfig{"negative_weight", "R = [0.1]", "R = [-0.1]", "field 'problem.R': has negative entries"},
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
        BadConfig{"huge_substeps", "dt = 0.05", "dt = 0.05\nsubsteps = -4294967295",
                  "field 'system.substeps': is -4294967295; expected an integer from 1 to 10000"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(SolveCommand, AMissingFileIsBadInput) {
  const auto r = test::run_cli("solve /nonexistent/problem.toml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/nonexistent/problem.toml: no such file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gpilqg
