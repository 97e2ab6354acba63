#include "gpilqg/experiments/import_report.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

namespace gpilqg {

namespace {

std::string unit_or_si(const ColumnMapping& c) { return c.unit.empty() ? "SI" : c.unit; }

}  // namespace

std::string format_import_report(const ImportReport& r, const std::filesystem::path& out) {
  std::string text;
  text += fmt::format("imported {} ({}) for {} into {}\n", r.log.string(), r.format, r.system, out.string());
  text += fmt::format("rows: {} read, {} used, {} dropped; {} samples written at dt = {:.6g} s ({})\n", r.rows_read, r.rows_used,
                      r.rows_dropped, r.samples_written, r.dt, r.dt_from_map ? "from the map" : "the median logged step");
  text += fmt::format("controls: {}\n", r.average_controls ? "averaged over each step" : "held (the control in force at each sample)");
  text += fmt::format("episodes: {} written; {} gap{} longer than {:.6g} s ({}) split the log; logged steps {:.6g} .. {:.6g} s\n",
                      r.episodes.size(), r.gaps, r.gaps == 1 ? "" : "s", r.max_gap, r.max_gap_from_map ? "from the map" : "3 dt",
                      r.step_min, r.step_max);
  for (const ColumnMapping& c : r.columns)
    text += fmt::format("  {:<12} <- {} [{}]\n", c.target, c.column, unit_or_si(c));
  for (const auto& [velocity, position] : r.estimated)
    text += fmt::format("  {:<12} <- d/dt {} (Savitzky-Golay)\n", velocity, position);
  if (r.estimator)
    text += fmt::format("velocity estimator: Savitzky-Golay, window {}, order {}: lag {:.6g} s, noise gain {:.4g} /s "
                        "({:.4g} /s at the first and last samples)\n",
                        r.estimator->window, r.estimator->order, r.estimator_lag, r.estimator_noise_gain,
                        r.estimator_end_noise_gain);
  std::string ignored;
  for (const std::string& name : r.ignored_columns) ignored += (ignored.empty() ? "" : ", ") + name;
  text += fmt::format("ignored columns: {}\n", ignored.empty() ? "none" : ignored);
  for (const DroppedPiece& d : r.dropped)
    text += fmt::format("dropped: episode {} from t = {:.6g} s to {:.6g} s, {} rows: {}\n", d.source_episode, d.t_start, d.t_end,
                        d.rows, d.reason);
  return text;
}

nlohmann::json import_report_json(const ImportReport& r, const std::filesystem::path& out) {
  using nlohmann::json;
  json columns = json::array();
  for (const ColumnMapping& c : r.columns)
    columns.push_back({{"target", c.target}, {"column", c.column}, {"unit", unit_or_si(c)}, {"scale", c.scale}});
  json velocities = nullptr;
  if (r.estimator) {
    json estimated = json::object();
    for (const auto& [velocity, position] : r.estimated) estimated[velocity] = position;
    velocities = {{"method", "savitzky_golay"},        {"window", r.estimator->window},
                  {"order", r.estimator->order},       {"estimated", estimated},
                  {"lag_s", r.estimator_lag},          {"noise_gain", r.estimator_noise_gain},
                  {"end_noise_gain", r.estimator_end_noise_gain}};
  }
  json episodes = json::array();
  for (const ImportedEpisode& e : r.episodes)
    episodes.push_back(
        {{"id", e.id}, {"source_episode", e.source_episode}, {"t_start", e.t_start}, {"rows", e.rows}, {"samples", e.samples}});
  json dropped = json::array();
  for (const DroppedPiece& d : r.dropped)
    dropped.push_back({{"source_episode", d.source_episode},
                       {"t_start", d.t_start},
                       {"t_end", d.t_end},
                       {"rows", d.rows},
                       {"reason", d.reason}});
  return {{"log", r.log.string()},
          {"map", r.map.string()},
          {"out", out.string()},
          {"format", r.format},
          {"system", r.system},
          {"rows", {{"read", r.rows_read}, {"used", r.rows_used}, {"dropped", r.rows_dropped}}},
          {"samples_written", r.samples_written},
          {"episodes", r.episodes.size()},
          {"dt", r.dt},
          {"dt_source", r.dt_from_map ? "map" : "median step"},
          {"max_gap", r.max_gap},
          {"max_gap_source", r.max_gap_from_map ? "map" : "3 dt"},
          {"controls", r.average_controls ? "average" : "hold"},
          {"logged_step", {{"min", r.step_min}, {"max", r.step_max}}},
          {"gaps_split", r.gaps},
          {"columns", columns},
          {"ignored_columns", r.ignored_columns},
          {"velocities", velocities},
          {"episode_list", episodes},
          {"dropped", dropped}};
}

}  // namespace gpilqg
