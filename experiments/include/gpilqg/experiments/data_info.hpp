#pragma once
/// @file data_info.hpp
/// `gpilqg data info FILE --system NAME [--json]`
/// (docs/command-line.md#gpilqg-data-info-file---system-name---json): a measurement file's summary
/// (gpilqg::summarize) as a table for the terminal or as one JSON document.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg {

/// The step shared by all episodes, or nullopt when they differ. Episodes agree when
/// dt_max - dt_min <= 1e-6 dt_max (the tolerance of the data contract); the value is then dt_min.
std::optional<double> common_dt(const MeasurementSummary& summary);

/// A table for the terminal: file, system, episodes, samples, dt (or its range), duration, then
/// one line per state and control with unit, min, max, mean and std. Ends with a newline.
std::string format_data_info(const std::filesystem::path& file, const MeasurementSummary& summary);

/// The same as a JSON object with the keys "file", "system", "episodes", "samples", "dt" (a number
/// when common_dt() has one, else null), "dt_min", "dt_max", "duration_s", and "states" and
/// "controls": arrays of {"name", "unit", "min", "max", "mean", "std"} in the system's order.
nlohmann::json data_info_json(const std::filesystem::path& file, const MeasurementSummary& summary);

}  // namespace gpilqg
