#pragma once
/// @file sweep_results_io.hpp
/// The result file of `gpilqg sweep` (docs/cluster.md): one group per grid point holding that point's
/// `gpilqg run` result (run_results_io.hpp), so everything that reads a run reads a point.
///
///   /            attrs: schema_version (1), gpilqg_version, created (UTC, ISO 8601), system,
///                sweep (the sweep file's text), grid_fields (the varied fields, in file order),
///                points (their number)
///   /point_<p>/  the run layout of grid point p (its root attributes on the group: config, the
///                point's full run config as TOML, seed, ...), plus attrs grid_values (the value of
///                each grid field as TOML, in grid_fields order) and label ("gp.backend = \"fitc\"")
///
/// Written to a temporary file renamed into place, like every result file.

#include <filesystem>
#include <vector>

#include "gpilqg/experiments/run_experiment.hpp"
#include "gpilqg/experiments/sweep_config.hpp"

namespace gpilqg {

/// `results[p]` belongs to sweep.points[p]. Throws std::runtime_error naming the file when writing fails.
void write_sweep_results(const std::filesystem::path& file, const SweepConfig& sweep, const std::vector<RunResults>& results);

}  // namespace gpilqg
