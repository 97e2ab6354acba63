#pragma once
/// @file tiny_run_config.hpp
/// The small configurations of the experiment tests: a `gpilqg run` configuration
/// (run_experiment_test.cpp, run_resume_test.cpp, hostile_cli_test.cpp): cart-pole, every algorithm,
/// a transfer task, in well under a second; and a `gpilqg plan` configuration.

#include "gpilqg/experiments/run_config.hpp"

namespace gpilqg::test {

/// Two 15-step tasks, one data round, small GPs and short PDDP solves: seconds, not minutes.
inline const char* const kTinyRun = R"(
[noise]
actuator_multiplicative = [0.02]
observation = [0.001, 0.001, 0.001, 0.001]
[loop]
iterations = 2
rollouts = 1
evaluation_rollouts = 2
[gp]
exact_points = 40
restarts = 0
max_evaluations = 40
[solver]
max_iterations = 30
[pddp]
max_iterations = 2
own = true
own_initial_rollouts = 1
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
[[tasks]]
name = "second"
x0 = [0.0, 0.0, -0.3, 0.0]
goal = [0.0, 0.0, 0.0, 0.0]
horizon = 15
Q = [1.0, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
track_line = false
transfer = true
)";

/// kTinyRun for the cart-pole.
inline RunConfig tiny_run_config() { return parse_run_config("cartpole", kTinyRun, "tiny.toml"); }

/// One cart-pole task as a `gpilqg plan` config (the cart-pole run defaults made explicit): the
/// problem of plan_cli_test.cpp's run, solved in well under a second.
inline const char* const kTinyPlan = R"([system]
name = "cartpole"
preset = "sim"
integrator = "rk4"
substeps = 10
dt = 0.05
[noise]
actuator_multiplicative = [0.02]
observation = [0.001, 0.001, 0.001, 0.001]
[problem]
horizon = 15
x0 = [0.0, 0.0, 0.3, 0.0]
goal = [0.0, 0.0, 0.0, 0.0]
Q = [1.0, 1.0, 1.0, 1.0]
R = [0.1]
Qf = [10.0, 10.0, 10.0, 10.0]
u_min = [-25.0]
u_max = [25.0]
u_init = [0.0]
[solver]
max_iterations = 30
tolerance = 1e-6
gradient_tolerance = 1e-4
[gp]
exact_points = 40
restarts = 0
max_evaluations = 40
)";

}  // namespace gpilqg::test
