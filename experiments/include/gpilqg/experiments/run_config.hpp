#pragma once
/// @file run_config.hpp
/// The configuration of `gpilqg run` (the paper's experiments). Every field has an embedded default
/// (experiments/configs/run_<system>.toml, compiled into the program), so `gpilqg run cartpole` needs
/// no file; `--config FILE` overrides fields: tables merge key by key, arrays (including [[tasks]])
/// are replaced whole, and a key the defaults do not have is an error naming the file and line.
///
///   [system]  name, dt, integrator ("euler"|"rk4"), substeps      (world, true model and simulator;
///             a MuJoCo model has neither integrator nor substeps: its own are the simulator)
///   [world]   model (a second model file), parameters (name = value): the real world, for systems
///             without a default config (MuJoCo models, plugins); the built-ins' is their "real" preset
///   [noise]   actuator_multiplicative (m), actuator_additive (m), observation (n)
///   [control] u_init (m), u_min, u_max (m, optional)
///   [[tasks]] name, x0, goal, horizon, Q, R, Qf, track_line, transfer
///   [loop]    iterations, rollouts, exploration (m), policy_tolerance, evaluation_rollouts
///   [gp]      backend, exact_points, inducing, frequencies, restarts, max_evaluations
///   [solver]  max_iterations, tolerance, gradient_tolerance, gp_algorithm ("robust_ilqg"|"ilqg")
///   [mpc]     enabled, horizon, first_solve_iterations, iterations_per_step
///   [pddp]    enabled, max_iterations, backend ("exact"|"fitc"|"ssgp"), own, own_initial_rollouts,
///             own_amplitude (m)

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/control/mpc.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/noise.hpp"
#include "gpilqg/experiments/gp_settings.hpp"

namespace gpilqg {

/// One task: a finite-horizon problem on the real world.
struct RunTask {
  std::string name;
  Vector x0, goal;
  int horizon = 0;
  Vector Q, R, Qf;          ///< diagonals: running cost dt (0.5 e'Qe + 0.5 u'Ru), terminal 0.5 e'Qf e
  bool track_line = false;  ///< e = x - x_ref(t) along the straight line x0 -> goal (the quadrotor's)
  bool transfer = false;    ///< starts from the data (and learned model) of the previous task
};

struct RunConfig {
  // [system]
  std::string system;
  double dt = 0.05;
  Integrator integrator = Integrator::RK4;
  int substeps = 10;
  // [world]
  std::string world_model;                         ///< another model file with the same joints and actuators
  std::map<std::string, double> world_parameters;  ///< parameter overrides of the world
  // [noise]
  ActuatorNoise noise;     ///< the world's process noise, known to every model (the paper's F)
  Vector observation_std;  ///< n entries
  // [control]
  Vector u_init, u_min, u_max;
  // [[tasks]]
  std::vector<RunTask> tasks;
  // [loop]
  int iterations = 5;
  int rollouts = 3;
  Vector exploration_std;
  double policy_tolerance = 0.02;
  int evaluation_rollouts = 5;
  // [gp]
  GpSettings gp;
  // [solver]
  DdpOptions solver;  ///< variant chosen per algorithm
  /// The variant GP-ILQG solves with: RobustILQG (the paper: F and the GP's G) or ILQG (an ablation
  /// that ignores the GP's uncertainty and plans on its mean).
  DdpVariant gp_variant = DdpVariant::RobustILQG;
  // [mpc]
  bool mpc = false;
  MpcOptions mpc_options;
  // [pddp]
  bool pddp = true;
  int pddp_max_iterations = 40;
  std::string pddp_backend = "exact";  ///< PDDP's GPs (sized by backend_settings): one with exact moment matching
  bool pddp_own = true;
  int pddp_own_initial_rollouts = 3;
  Vector pddp_own_amplitude;

  /// The full effective config as TOML text (defaults merged with the user's file): what the result
  /// stores in its `config` attribute.
  std::string text;
};

/// The embedded default config of a system ("cartpole", "quadrotor") as TOML text. Throws InputError
/// listing the systems for an unknown name.
const std::string& default_run_config_text(const std::string& system);

/// The defaults of `system`, overridden by `override_file` when given. Throws InputError naming the
/// file, line and field for unknown keys, wrong types or sizes and invalid values.
RunConfig load_run_config(const std::string& system, const std::optional<std::filesystem::path>& override_file);

/// The same from TOML text (`source` names it in errors), for tests and the resume path.
RunConfig parse_run_config(const std::string& system, const std::string& override_text, const std::string& source);

}  // namespace gpilqg
