#include "gpilqg/experiments/data_info.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>

namespace gpilqg {

namespace {

/// Relative agreement of the episodes' steps, as in the data contract
/// (docs/formats.md#measurement-data-csv-and-hdf5).
constexpr double kDtAgreement = 1e-6;

/// What a statistic beyond the largest double reads as, in the table and in JSON (where a number
/// would be written as null): only a duration or step of times spanning more than 1.8e308 s.
constexpr const char* kNotRepresentable = "not representable (beyond 1.8e308)";

/// A statistic as JSON: the number, or kNotRepresentable when it is not finite.
nlohmann::json statistic(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(kNotRepresentable);
}

/// A statistic in the table: "{:.6g}" with `suffix`, or kNotRepresentable.
std::string statistic_text(double value, const char* suffix = "") {
  return std::isfinite(value) ? fmt::format("{:.6g}{}", value, suffix) : kNotRepresentable;
}

nlohmann::json column_json(const ColumnSummary& c) {
  return {{"name", c.name},           {"unit", c.unit},           {"min", statistic(c.min)},
          {"max", statistic(c.max)}, {"mean", statistic(c.mean)}, {"std", statistic(c.std)}};
}

nlohmann::json columns_json(const std::vector<ColumnSummary>& columns) {
  nlohmann::json array = nlohmann::json::array();
  for (const ColumnSummary& c : columns) array.push_back(column_json(c));
  return array;
}

}  // namespace

std::optional<double> common_dt(const MeasurementSummary& summary) {
  if (summary.dt_max == summary.dt_min || summary.dt_max - summary.dt_min <= kDtAgreement * std::abs(summary.dt_max))
    return summary.dt_min;
  return std::nullopt;
}

std::string format_data_info(const std::filesystem::path& file, const MeasurementSummary& summary) {
  fmt::memory_buffer out;
  auto line = [&](const char* key, const std::string& value) {
    fmt::format_to(std::back_inserter(out), "{:<10}{}\n", key, value);
  };
  line("file", file.string());
  line("system", summary.system);
  line("episodes", std::to_string(summary.episodes));
  line("samples", std::to_string(summary.samples));
  if (const auto dt = common_dt(summary))
    line("dt", statistic_text(*dt, " s"));
  else if (std::isfinite(summary.dt_max))
    line("dt", fmt::format("{:.6g} to {:.6g} s (differs between episodes)", summary.dt_min, summary.dt_max));
  else
    line("dt", fmt::format("{} to {} (differs between episodes)", statistic_text(summary.dt_min, " s"),
                           statistic_text(summary.dt_max, " s")));
  line("duration", statistic_text(summary.duration, " s"));
  // The provenance of the states (HDF5 attribute estimated_states; a CSV file cannot hold it).
  line("estimated", summary.estimated_states.empty()
                        ? std::string("none (every state measured)")
                        : fmt::format("{} (from other states, e.g. by gpilqg data import)",
                                      fmt::join(summary.estimated_states, ", ")));

  std::size_t name_width = 4, unit_width = 4;
  for (const auto* columns : {&summary.states, &summary.controls})
    for (const ColumnSummary& c : *columns) {
      name_width = std::max(name_width, c.name.size());
      unit_width = std::max(unit_width, c.unit.size());
    }
  fmt::format_to(std::back_inserter(out), "\n{:<9}{:<{}}  {:<{}}{:>13}{:>13}{:>13}{:>13}\n", "kind", "name",
                 name_width, "unit", unit_width, "min", "max", "mean", "std");
  auto rows = [&](const char* kind, const std::vector<ColumnSummary>& columns) {
    for (const ColumnSummary& c : columns)
      fmt::format_to(std::back_inserter(out), "{:<9}{:<{}}  {:<{}}{:>13.6g}{:>13.6g}{:>13.6g}{:>13.6g}\n", kind,
                     c.name, name_width, c.unit, unit_width, c.min, c.max, c.mean, c.std);
  };
  rows("state", summary.states);
  rows("control", summary.controls);
  return fmt::to_string(out);
}

nlohmann::json data_info_json(const std::filesystem::path& file, const MeasurementSummary& summary) {
  const auto dt = common_dt(summary);
  return {{"file", file.string()},
          {"system", summary.system},
          {"episodes", summary.episodes},
          {"samples", summary.samples},
          {"dt", dt ? statistic(*dt) : nlohmann::json(nullptr)},  // null: the episodes' steps differ
          {"dt_min", statistic(summary.dt_min)},
          {"dt_max", statistic(summary.dt_max)},
          {"duration_s", statistic(summary.duration)},
          {"estimated_states", summary.estimated_states},  // [] when every state was measured
          {"states", columns_json(summary.states)},
          {"controls", columns_json(summary.controls)}};
}

}  // namespace gpilqg
