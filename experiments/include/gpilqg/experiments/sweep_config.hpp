#pragma once
/// @file sweep_config.hpp
/// `gpilqg sweep SWEEP.toml`: a grid of `gpilqg run` configs times seeds
/// (docs/command-line.md#gpilqg-sweep-sweeptoml-options; docs/cluster.md#sweeps). The file:
///
///   system = "cartpole"        # required: as `gpilqg run SYSTEM`
///   config = "base.toml"       # optional: the run config every point starts from (relative to this
///                              # file; default: the system's embedded defaults)
///   seeds = 4                  # optional, default 1: seeds first_seed, first_seed + 1, ...
///   first_seed = 1             # optional, default 1
///   iterations = 3             # optional: overrides loop.iterations, as `gpilqg run --iterations`
///   out = "sweep.h5"           # optional, default "<file stem>.h5" beside this file
///   [grid]                     # one entry per varied field: its dotted name in the run config and
///   "gp.backend" = ["exact", "fitc"]           # the values to try (each value as the field takes it)
///   "noise.actuator_multiplicative" = [[0.02], [0.1]]
///
/// The grid is the Cartesian product of the fields' values; points are numbered with the field written
/// last varying fastest. A field must exist in the run config (e.g. "loop.rollouts", "gp.exact_points",
/// "tasks[1].horizon"); each point's config is then read and validated exactly like a run config, and
/// errors name this file, the field and the point.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "gpilqg/experiments/run_config.hpp"

namespace gpilqg {

struct SweepPoint {
  std::vector<std::pair<std::string, std::string>> values;  ///< (field, value as TOML) per grid field
  RunConfig config;                                         ///< the full run config of this point
  /// "gp.backend = \"fitc\", loop.rollouts = 2"
  std::string label() const;
};

struct SweepConfig {
  std::filesystem::path file;
  std::string text;          ///< the sweep file as read
  std::string system;
  std::vector<std::uint64_t> seeds;
  std::filesystem::path out;
  std::filesystem::path config;     ///< the base run config named by `config` (empty when absent)
  std::vector<std::string> fields;  ///< the grid's fields in file order
  std::vector<SweepPoint> points;
};

/// Reads and validates the sweep file and every point's run config. Throws InputError naming the file,
/// line and field: unknown keys, a missing `system`, an empty grid or value list, a field the run
/// config does not have, a value the field does not accept (naming the point), more than
/// kMaxSweepPoints points.
SweepConfig load_sweep_config(const std::filesystem::path& file);

inline constexpr int kMaxSweepPoints = 10000;

}  // namespace gpilqg
