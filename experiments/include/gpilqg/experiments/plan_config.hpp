#pragma once
/// @file plan_config.hpp
/// The config of `gpilqg plan` (docs/formats.md#problem-config-gpilqg-solve-and-gpilqg-plan): the
/// `gpilqg solve` schema (solve_config.hpp) plus an optional [gp] table (gp_settings.hpp; missing
/// fields take GpSettings' defaults) and an optional [noise] observation (n standard deviations, as in
/// `gpilqg run`'s config).
///
/// [solver] algorithm is the solver of the rounds with data: "robust_ilqg" (the default, the paper's
/// Robust-iLQG with the GP's uncertainty G) or "ilqg" (the GP's mean only). The round without data is
/// iLQG on the simulator whatever it says, as in `gpilqg run`.

#include <filesystem>

#include "gpilqg/experiments/gp_settings.hpp"
#include "gpilqg/experiments/solve_config.hpp"

namespace gpilqg {

class TomlFields;

struct PlanConfig {
  SolveConfig problem;  ///< the simulator (the GP's mean function), its noise F, the task and the solver
  GpSettings gp;
  /// [noise] observation: the sensors' noise std per state (optional, zeros when absent). With the
  /// process noise F it sets each residual GP's floor on its noise std (gp/noise_floor.hpp).
  Vector observation_std;
};

/// Reads and validates a plan config; throws InputError naming the file, line and field.
PlanConfig read_plan_config(const std::filesystem::path& file);
/// The same from a parsed config (e.g. TOML text); errors name the reader's source.
PlanConfig read_plan_config(const TomlFields& fields);

}  // namespace gpilqg
