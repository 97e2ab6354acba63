#include "gpilqg/experiments/data_info.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <nlohmann/json.hpp>

namespace gpilqg {

namespace {

/// Relative agreement of the episodes' steps, as in the data contract (DESIGN.md section 4).
constexpr double kDtAgreement = 1e-6;

nlohmann::json column_json(const ColumnSummary& c) {
  return {{"name", c.name}, {"unit", c.unit}, {"min", c.min}, {"max", c.max}, {"mean", c.mean}, {"std", c.std}};
}

nlohmann::json columns_json(const std::vector<ColumnSummary>& columns) {
  nlohmann::json array = nlohmann::json::array();
  for (const ColumnSummary& c : columns) array.push_back(column_json(c));
  return array;
}

}  // namespace

std::optional<double> common_dt(const MeasurementSummary& summary) {
  if (summary.dt_max - summary.dt_min <= kDtAgreement * std::abs(summary.dt_max)) return summary.dt_min;
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
    line("dt", fmt::format("{:.6g} s", *dt));
  else
    line("dt", fmt::format("{:.6g} to {:.6g} s (differs between episodes)", summary.dt_min, summary.dt_max));
  line("duration", fmt::format("{:.6g} s", summary.duration));

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
          {"dt", dt ? nlohmann::json(*dt) : nlohmann::json(nullptr)},
          {"dt_min", summary.dt_min},
          {"dt_max", summary.dt_max},
          {"duration_s", summary.duration},
          {"states", columns_json(summary.states)},
          {"controls", columns_json(summary.controls)}};
}

}  // namespace gpilqg
