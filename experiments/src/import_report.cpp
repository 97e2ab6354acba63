#include "gpilqg/experiments/import_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

namespace gpilqg {

namespace {

std::string unit_or_si(const ColumnMapping& c) { return c.unit.empty() ? "SI" : c.unit; }

/// How many gaps the text lists; the JSON report lists all of them.
constexpr std::size_t kGapsListed = 10;

/// The map's episode column, or nullptr when the whole log is one record.
const ColumnMapping* episode_column(const ImportReport& r) {
  for (const ColumnMapping& c : r.columns)
    if (c.target == "episode") return &c;
  return nullptr;
}

/// The smallest max_gap, written with two significant digits, that keeps a gap of `seconds` inside
/// a record (a step equal to max_gap does not split), as the map's text: "0.43" for 0.4213.
std::string max_gap_keeping(double seconds) {
  const double digit = std::pow(10.0, std::floor(std::log10(seconds)) - 1.0);
  double value = std::ceil(seconds / digit) * digit;
  std::string text = fmt::format("{:.6g}", value);
  while (std::stod(text) < seconds) text = fmt::format("{:.6g}", value += digit);
  return text;
}

/// The lines on the records max_gap cut into several pieces, the gaps (the first kGapsListed), and
/// how to keep each record whole; nothing when no record was cut.
std::string format_splits(const ImportReport& r) {
  if (r.gap_list.empty()) return "";
  const ColumnMapping* episodes = episode_column(r);
  const std::string limit = fmt::format("max_gap = {:.6g} s ({})", r.max_gap, r.max_gap_from_map ? "from the map" : "the default, 3 dt");
  auto pieces = [](const LogRecord& record) {
    const long gaps = record.pieces - 1, dropped = record.pieces - record.episodes;
    return fmt::format("{} pieces at {} gap{}: {} episode{} written{}", record.pieces, gaps, gaps == 1 ? "" : "s",
                       record.episodes, record.episodes == 1 ? "" : "s",
                       dropped > 0 ? fmt::format(", {} dropped as too short", dropped) : "");
  };
  std::string text;
  if (episodes == nullptr) {
    text += fmt::format("split: {} cut the log's one record into {}\n", limit, pieces(r.records.front()));
  } else {
    const long cut = std::count_if(r.records.begin(), r.records.end(), [](const LogRecord& rec) { return rec.pieces > 1; });
    text += fmt::format("split: {} cut {} of the log's {} records (values of '{}'):\n", limit, cut, r.records.size(),
                        episodes->column);
    for (const LogRecord& record : r.records)
      if (record.pieces > 1) text += fmt::format("  episode {}: {}\n", record.source_episode, pieces(record));
  }
  for (std::size_t i = 0; i < std::min(r.gap_list.size(), kGapsListed); ++i) {
    const SplitGap& gap = r.gap_list[i];
    text += fmt::format("  gap {}at t = {:.6g} s: {:.6g} s = {:.3g} dt\n",
                        episodes == nullptr ? "" : fmt::format("in episode {} ", gap.source_episode), gap.t_start,
                        gap.length(), gap.length() / r.dt);
  }
  if (r.gap_list.size() > kGapsListed)
    text += fmt::format("  ... and {} more (--json lists every gap in gap_list)\n", r.gap_list.size() - kGapsListed);
  const auto longest = std::max_element(r.gap_list.begin(), r.gap_list.end(),
                                        [](const SplitGap& a, const SplitGap& b) { return a.length() < b.length(); });
  text += fmt::format(
      "  to keep {} in one piece, raise max_gap in the map to the longest gap ({:.6g} s) or more: [resample] max_gap = {} "
      "(the states are then interpolated linearly across each gap and the controls held)\n",
      episodes == nullptr ? "the record" : "each record", longest->length(), max_gap_keeping(longest->length()));
  return text;
}

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
  if (!r.estimated.empty()) {
    std::string extension = out.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
    std::vector<std::string> names;
    for (const auto& estimated : r.estimated) names.push_back(estimated.first);
    text += extension == ".csv"
                ? fmt::format("note: a CSV file cannot record that {} {} estimated, so they read back as measured; write "
                              ".h5 to keep it (the diagnosis chooses its criterion by it)\n",
                              fmt::join(names, ", "), names.size() == 1 ? "was" : "were")
                : fmt::format("provenance: {} recorded as estimated (attribute estimated_states)\n", fmt::join(names, ", "));
  }
  std::string ignored;
  for (const std::string& name : r.ignored_columns) ignored += (ignored.empty() ? "" : ", ") + name;
  text += fmt::format("ignored columns: {}\n", ignored.empty() ? "none" : ignored);
  for (const DroppedPiece& d : r.dropped)
    text += fmt::format("dropped: episode {} from t = {:.6g} s to {:.6g} s, {} rows: {}\n", d.source_episode, d.t_start, d.t_end,
                        d.rows, d.reason);
  text += format_splits(r);  // last: what to change in the map when a record was cut
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
  json records = json::array();
  for (const LogRecord& record : r.records)
    records.push_back({{"source_episode", record.source_episode},
                       {"rows", record.rows},
                       {"pieces", record.pieces},
                       {"episodes", record.episodes}});
  json gaps = json::array();
  for (const SplitGap& gap : r.gap_list)
    gaps.push_back({{"source_episode", gap.source_episode},
                    {"t_start", gap.t_start},
                    {"t_end", gap.t_end},
                    {"length", gap.length()},
                    {"length_dt", gap.length() / r.dt}});
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
          {"records", records},
          {"gap_list", gaps},
          {"columns", columns},
          {"ignored_columns", r.ignored_columns},
          {"velocities", velocities},
          {"episode_list", episodes},
          {"dropped", dropped}};
}

}  // namespace gpilqg
