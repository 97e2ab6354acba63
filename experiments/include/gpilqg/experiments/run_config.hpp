#pragma once
/// @file run_config.hpp
/// The configuration of `gpilqg run` (the paper's experiments). Every field has an embedded default
/// (experiments/configs/run_<system>.toml, compiled into the program), so `gpilqg run cartpole` needs
/// no file; `--config FILE` overrides fields: tables merge key by key, arrays (including [[tasks]])
/// are replaced whole, and a key the defaults do not have is an error naming the file and line.
///
///   [system]  name, dt, integrator ("euler"|"rk4"), substeps      (world, true model and simulator;
///             a MuJoCo model has neither integrator nor substeps: its own are the simulator);
///             model (optional): a model file of `gpilqg diagnose` as the simulator
///   [world]   model (a second model file, or a model file of the diagnosis), parameters (name =
///             value): the real world; without them the system's "real" preset
///   [noise]   actuator_multiplicative (m), actuator_additive (m), observation (n)
///   [control] u_init (m), u_min, u_max (m, optional)
///   [[tasks]] name, x0, goal, horizon, Q, R, Qf, track_line, transfer
///   [loop]    iterations, rollouts, exploration (m), policy_tolerance, evaluation_rollouts
///   [diagnosis] after_round (optional): diagnose the data after this round (loop_diagnosis.hpp)
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
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/noise.hpp"
#include "gpilqg/core/output_path.hpp"
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

/// Every field is read from the config: the embedded defaults of the system (the only source of
/// default values, experiments/configs/run_<system>.toml) merged with the user's file. The
/// initial values below are placeholders, never defaults.
struct RunConfig {
  // [system]
  std::string system;
  double dt = 0.0;
  Integrator integrator = Integrator::RK4;
  int substeps = 0;
  /// The simulator: [system] model (a model file of the diagnosis, config_model.hpp) or the "sim"
  /// preset. GP-ILQG's residual GP has it as its mean function.
  ModelSpec simulator;
  // [world]
  /// The real world: the "real" preset, another model file with the same joints and actuators, or a
  /// model file of the diagnosis ([world] model), with [world] parameters as overrides.
  ModelSpec world;
  // [noise]
  ActuatorNoise noise;     ///< the world's process noise, known to every model (the paper's F)
  Vector observation_std;  ///< n entries
  // [control]
  Vector u_init, u_min, u_max;
  // [[tasks]]
  std::vector<RunTask> tasks;
  // [loop]
  int iterations = 0;
  int rollouts = 0;
  Vector exploration_std;
  double policy_tolerance = 0.0;
  int evaluation_rollouts = 0;
  // [diagnosis]
  /// after_round: the round after whose rollouts gp_ilqg diagnoses its data and, when the verdict is
  /// "explained", plans on with the diagnosed model as the simulator (loop_diagnosis.hpp); -1: never.
  /// Optional, -1 when absent.
  int diagnose_after = -1;
  // [gp]
  GpSettings gp;
  // [solver]
  DdpOptions solver;  ///< variant chosen per algorithm; no wall-time limit (iterations are the only one)
  /// The variant GP-ILQG solves with: RobustILQG (the paper: F and the GP's G) or ILQG (an ablation
  /// that ignores the GP's uncertainty and plans on its mean).
  DdpVariant gp_variant = DdpVariant::RobustILQG;
  // [mpc]
  bool mpc = false;
  MpcOptions mpc_options;
  // [pddp]
  bool pddp = false;
  int pddp_max_iterations = 0;
  std::string pddp_backend;  ///< PDDP's GPs (sized by gp.backend_settings): one with exact moment matching
  bool pddp_own = false;
  int pddp_own_initial_rollouts = 0;
  Vector pddp_own_amplitude;

  /// The full effective config as TOML text (defaults merged with the user's file): what the result
  /// stores in its `config` attribute.
  std::string text;
  /// The files the config names (config_files, config_model.hpp): system.name when it is a MuJoCo
  /// model or URDF, system.model, world.model; and their texts as the run read them
  /// (config_files_text), which the result stores in its `model_files` attribute: a resumed run and
  /// the parts of a merge must have read the same.
  std::vector<NamedInput> files;
  std::string files_text;
};

/// The embedded default config of a system ("cartpole", "quadrotor") as TOML text. Throws InputError
/// listing the systems for an unknown name.
const std::string& default_run_config_text(const std::string& system);

/// The defaults of `system`, overridden by `override_file` when given. Throws InputError naming the
/// file, line and field for unknown keys, wrong types or sizes and invalid values, and naming the file
/// when it is not a readable regular file of at most kMaxConfigFileBytes (input_file.hpp).
RunConfig load_run_config(const std::string& system, const std::optional<std::filesystem::path>& override_file);

/// The same from TOML text (`source` names it in errors), for tests and the resume path.
RunConfig parse_run_config(const std::string& system, const std::string& override_text, const std::string& source);

/// `config` with loop.iterations = `iterations` (1 to kMaxLoopIterations), in its stored text too, so
/// that the result keeps what ran: `run --iterations`, a sweep file's `iterations`, Python's
/// run(iterations=). Throws InputError naming `option` when [diagnosis] after_round is then no round
/// of the loop.
RunConfig with_iterations(RunConfig config, int iterations, const std::string& option);

}  // namespace gpilqg
