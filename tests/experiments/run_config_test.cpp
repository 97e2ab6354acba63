/// `gpilqg run` configs: the embedded defaults parse for both systems, a user file overrides fields
/// (tables merge, [[tasks]] are replaced), and bad input names the file, the line and the field.

#include "gpilqg/experiments/run_config.hpp"

#include <gtest/gtest.h>

#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg {
namespace {

std::string error_of(const std::string& system, const std::string& text) {
  try {
    parse_run_config(system, text, "user.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RunConfig, EmbeddedDefaultsDescribeThePapersExperiments) {
  const RunConfig cartpole = parse_run_config("cartpole", "", "");
  ASSERT_EQ(cartpole.tasks.size(), 2u);
  EXPECT_NEAR(cartpole.tasks[0].x0(2), M_PI / 4, 1e-15);   // theta = pi/4 ...
  EXPECT_NEAR(cartpole.tasks[1].x0(2), -M_PI / 4, 1e-15);  // ... then -pi/4 from the first task's data
  EXPECT_FALSE(cartpole.tasks[0].transfer);
  EXPECT_TRUE(cartpole.tasks[1].transfer);
  EXPECT_EQ(cartpole.gp.backend, "exact");
  EXPECT_EQ(cartpole.gp.backend_settings.exact_points, 600);  // twice the paper's subsample (README: why)
  EXPECT_EQ(cartpole.gp_variant, DdpVariant::RobustILQG);
  EXPECT_FALSE(cartpole.mpc);

  const RunConfig quadrotor = parse_run_config("quadrotor", "", "");
  ASSERT_EQ(quadrotor.tasks.size(), 2u);
  EXPECT_TRUE(quadrotor.mpc);
  EXPECT_TRUE(quadrotor.tasks[0].track_line);
  EXPECT_DOUBLE_EQ(quadrotor.tasks[0].goal(0), 4.0);
  EXPECT_DOUBLE_EQ(quadrotor.tasks[1].goal(2), 7.0);
  EXPECT_GT(quadrotor.tasks[0].Q(2), quadrotor.tasks[0].Q(0));  // height weighted higher
  // The stored text is the full config: it parses back to the same values.
  const RunConfig again = parse_run_config("quadrotor", quadrotor.text, "stored");
  EXPECT_EQ(again.text, quadrotor.text);
  EXPECT_EQ(again.tasks[1].name, quadrotor.tasks[1].name);
}

TEST(RunConfig, UserFileOverridesFieldsAndReplacesTasks) {
  const RunConfig c = parse_run_config("cartpole", R"(
[loop]
iterations = 2
[gp]
backend = "fitc"
inducing = 40
[[tasks]]
name = "short"
x0 = [0.0, 0.0, 0.5, 0.0]
goal = [0.0, 0.0, 3.14, 0.0]
horizon = 10
Q = [0.0, 0.0, 0.0, 0.0]
R = [0.1]
Qf = [1.0, 1.0, 1.0, 1.0]
track_line = false
transfer = false
)", "user.toml");
  EXPECT_EQ(c.iterations, 2);
  EXPECT_EQ(c.rollouts, 5);  // untouched defaults stay
  EXPECT_EQ(c.gp.backend, "fitc");
  EXPECT_EQ(c.gp.backend_settings.inducing, 40);
  ASSERT_EQ(c.tasks.size(), 1u);
  EXPECT_EQ(c.tasks[0].horizon, 10);
  EXPECT_NE(c.text.find("inducing = 40"), std::string::npos);
}

TEST(RunConfig, BadInputNamesFileLineAndField) {
  EXPECT_EQ(error_of("cartpole", "[loop]\niteratons = 3\n"),
            "user.toml:line 2: unknown field 'loop.iteratons'; expected one of: evaluation_rollouts, exploration, "
            "iterations, policy_tolerance, rollouts");
  EXPECT_NE(error_of("cartpole", "[noise]\nobservation = [0.1, 0.1]\n").find("user.toml:line 2: field 'noise.observation': has 2 entries; expected 4"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[gp]\nbackend = \"gpflow\"\n").find("unknown GP backend 'gpflow'"), std::string::npos);
  EXPECT_NE(error_of("cartpole", "[loop]\nrollouts = 0\n").find("field 'loop.rollouts': is 0; expected an integer from 1 to 100000"),
            std::string::npos);
  // The documented limits (limits.hpp) hold before anything is allocated.
  EXPECT_NE(error_of("cartpole", "[loop]\niterations = 1000000000\n").find("field 'loop.iterations': is 1000000000; expected an integer from 1 to 1000"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[gp]\nrestarts = 1000000000\n").find("field 'gp.restarts': is 1000000000; expected an integer from 0 to 1000"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[gp]\nfrequencies = 100000000\n").find("field 'gp.frequencies': is 100000000; expected an integer from 1 to 4096"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[system]\nname = \"quadrotor\"\n").find("but the command runs 'cartpole'"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[loop\n").find("user.toml:line 1"), std::string::npos);
  EXPECT_NE(error_of("cartpole", "[solver]\ngp_algorithm = \"pddp\"\n").find("field 'solver.gp_algorithm'"), std::string::npos);
  // One [[tasks]] table with the given start and transfer flag.
  auto one_task = [](const std::string& x0, const std::string& transfer) {
    return "[[tasks]]\nname = \"a\"\nx0 = " + x0 +
           "\ngoal = [0.0, 0.0, 3.14, 0.0]\nhorizon = 10\nQ = [0.0, 0.0, 0.0, 0.0]\nR = [0.1]\n"
           "Qf = [1.0, 1.0, 1.0, 1.0]\ntrack_line = false\ntransfer = " + transfer + "\n";
  };
  const std::string first_transfer = error_of("cartpole", one_task("[0.0, 0.0, 0.5, 0.0]", "true"));
  EXPECT_NE(first_transfer.find("user.toml:line 10: field 'tasks[0].transfer'"), std::string::npos) << first_transfer;
  // State-valued fields beyond the divergence bound (a start that counts as diverged) are bad input.
  const std::string far_start = error_of("cartpole", one_task("[1e300, 0.0, 0.5, 0.0]", "false"));
  EXPECT_EQ(far_start, "user.toml:line 3: field 'tasks[0].x0': entry 0 is 1e+300; expected |value| <= 1e+12 (beyond "
                       "it a state counts as diverged)");
  EXPECT_NE(error_of("cartpole", "[noise]\nobservation = [0.1, 2e12, 0.1, 0.1]\n")
                .find("field 'noise.observation': entry 1 is 2e+12; expected |value| <= 1e+12"),
            std::string::npos);
  EXPECT_NE(error_of("cartpole", "[control]\nu_init = [-1e13]\n").find("field 'control.u_init': entry 0 is -1e+13"),
            std::string::npos);
  EXPECT_THROW(load_run_config("cartpole", std::filesystem::path("/no/such/run.toml")), InputError);
  EXPECT_THROW(default_run_config_text("pendulum"), InputError);
}

TEST(RunConfig, PddpBackendIsOneWithExactMomentMatching) {
  EXPECT_EQ(parse_run_config("cartpole", "", "").pddp_backend, "exact");
  EXPECT_EQ(parse_run_config("quadrotor", "", "").pddp_backend, "exact");
  EXPECT_EQ(parse_run_config("cartpole", "[pddp]\nbackend = \"ssgp\"\n", "user.toml").pddp_backend, "ssgp");
  for (const char* bad : {"compact", "fitcc"}) {
    const std::string error = error_of("cartpole", std::string("[pddp]\nbackend = \"") + bad + "\"\n");
    EXPECT_NE(error.find("user.toml:line 2: field 'pddp.backend'"), std::string::npos) << error;
    EXPECT_NE(error.find("the backends that can are exact, fitc, ssgp"), std::string::npos) << error;
  }
  EXPECT_NE(error_of("cartpole", "[pddp]\nbackend = \"compact\"\n").find("Wendland"), std::string::npos);
}

}  // namespace
}  // namespace gpilqg
