#pragma once
/// @file import_report.hpp
/// The report of `gpilqg data import` (docs/data-import.md, "The report"): what was kept, resampled,
/// dropped and ignored, as text for the terminal or as one JSON document for --json.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "gpilqg/core/log_import.hpp"

namespace gpilqg {

/// A few lines for the terminal, ending with a newline. When max_gap cut a record, "split:" lines say
/// into how many pieces, list the first 10 gaps and give the max_gap that keeps each record whole.
std::string format_import_report(const ImportReport& report, const std::filesystem::path& out);

/// The JSON object: "log", "map", "out", "format", "system", "rows": {"read", "used", "dropped"},
/// "samples_written", "episodes" (count), "dt", "dt_source" ("map" or "median step"), "max_gap",
/// "max_gap_source" ("map" or "3 dt"), "controls" ("hold" or "average"), "logged_step": {"min", "max"}, "gaps_split",
/// "records": [{"source_episode", "rows", "pieces", "episodes"}] (what max_gap made of each record),
/// "gap_list": [{"source_episode", "t_start", "t_end", "length", "length_dt"}] (every gap), "columns": [{"target",
/// "column", "unit", "scale"}], "ignored_columns": [names], "velocities": null or {"method", "window",
/// "order", "estimated": {target: position}, "lag_s", "noise_gain", "end_noise_gain"}, "episode_list":
/// [{"id", "source_episode", "t_start", "rows", "samples"}], "dropped": [{"source_episode", "t_start",
/// "t_end", "rows", "reason"}].
nlohmann::json import_report_json(const ImportReport& report, const std::filesystem::path& out);

}  // namespace gpilqg
