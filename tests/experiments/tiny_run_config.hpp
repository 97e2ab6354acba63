#pragma once
/// @file tiny_run_config.hpp
/// The `gpilqg run` configuration of the experiment tests (run_experiment_test.cpp,
/// run_resume_test.cpp): cart-pole, every algorithm, a transfer task, in well under a second.

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

}  // namespace gpilqg::test
