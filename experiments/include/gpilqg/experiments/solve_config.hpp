#pragma once
/// @file solve_config.hpp
/// One trajectory-optimisation problem described in TOML (`gpilqg solve`; docs/formats.md, "Problem config"):
///
///   [system]   name, preset ("sim"|"real") or model (a model file of `gpilqg diagnose`,
///              config_model.hpp), integrator ("euler"|"rk4"), dt, substeps (optional)
///   [noise]    actuator_additive, actuator_multiplicative (m entries), state (n entries)   optional
///   [problem]  horizon, x0, goal, Q, R, Qf (diagonals), u_min, u_max (optional), u_init (optional, m)
///   [solver]   algorithm ("ilqr"|"ilqg"|"robust_ilqg"), max_iterations, tolerance (relative cost
///              change), gradient_tolerance, regularization ("control"|"value"), max_seconds (optional)
///
/// Running cost dt (0.5 e'Qe + 0.5 u'Ru), terminal 0.5 e'Qf e, e = x - goal. Unknown fields, wrong
/// sizes and non-finite numbers are errors naming the file, line and field.

#include <filesystem>
#include <string>
#include <vector>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/noise.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {

class TomlFields;

struct SolveConfig {
  std::string system = "cartpole";
  /// The model planned with: [system] model, or the system at [system] preset (config_model.hpp).
  ModelSpec simulator;
  Integrator integrator = Integrator::Euler;
  double dt = 0.05;
  int substeps = 1;
  ActuatorNoise noise;
  int horizon = 100;
  Vector x0, goal, Q, R, Qf;
  Vector u_min, u_max;  ///< empty: unconstrained
  Vector u_init;        ///< constant initial control (empty: zero)
  DdpOptions solver;
  /// The files the config names (config_files, config_model.hpp): system.name when it is a MuJoCo
  /// model or URDF, system.model. A command that reads the config must not overwrite them.
  std::vector<NamedInput> files;
};

/// Reads and validates a config; throws InputError naming the file, line and field.
SolveConfig read_solve_config(const std::filesystem::path& file);

/// The same schema inside a config with more (`gpilqg plan`'s [gp] and [noise] observation):
/// `extra_sections` are allowed beside the four above and `extra_noise_keys` in [noise] (the caller
/// reads them), and [solver] algorithm defaults to `default_algorithm`.
SolveConfig read_solve_config(const TomlFields& fields, const std::vector<std::string>& extra_sections,
                              const std::string& default_algorithm,
                              const std::vector<std::string>& extra_noise_keys = {});

/// The config's simulator: [system] (its model or preset, integrator, sub-steps) with [noise], at step dt.
std::shared_ptr<const StepModel> make_solve_model(const SolveConfig& config);

/// The config's cost: dt (0.5 e'Qe + 0.5 u'Ru) per step and 0.5 e'Qf e at the end, e = x - goal.
QuadraticCost make_solve_cost(const SolveConfig& config);

/// A solved config and where its solve started.
struct SolvedConfig {
  DdpResult result;
  std::string start;  ///< ReferencePlans::start_name: "the usual start" (u_init) or "the plan on ..."
};

/// Builds the model and cost of the config and solves it from u_init; when [system] model is not the
/// preset alone, also from the preset's plan replayed on the model (reference_plans.hpp), keeping the
/// cheaper start on the model (control/best_start.hpp).
SolvedConfig solve_config(const SolveConfig& config);

/// Why the initial rollout of a solve ended with termination InitialRolloutDiverged, given `cost`,
/// the config's cost of the trajectory the solver returns: the states reached before the divergence
/// bound (the last one repeated) and the initial controls. Finite: the states left the divergence
/// bound (a state not finite or beyond kDivergedStateMagnitude) and were cut there. Not finite: no
/// state was cut, the cost itself overflowed (the config's weights are bounded by
/// limits::kMaxCostWeight so that this needs a horizon times dt beyond any real problem). The text
/// completes "the initial controls ..." and ends with what to change.
std::string initial_rollout_failure(double cost);

}  // namespace gpilqg
