/// The import pipeline of log_import.hpp: resolve the map's columns in the log, group rows into
/// episodes, split at gaps, resample, estimate missing velocities, and count everything.

#include "gpilqg/core/log_import.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/map_patterns.hpp"
#include "gpilqg/core/resampling.hpp"
#include "gpilqg/core/savitzky_golay.hpp"

namespace gpilqg {

std::string MapOrigin::location() const { return line > 0 ? fmt::format("line {}", line) : std::string(); }

namespace {

[[noreturn]] void map_error(const MapOrigin& origin, const std::string& problem, const std::string& expected) {
  throw DataError(origin.file, origin.location(), fmt::format("field '{}': {}", origin.field, problem), expected);
}

const char* format_name(LogFormat format) {
  switch (format) {
    case LogFormat::Csv: return "csv";
    case LogFormat::Mat: return "mat";
    case LogFormat::Hdf5: return "hdf5";
  }
  return "";
}

/// The log column a mapping names, scaled to SI; fails naming the map entry or the log's column.
Vector mapped_values(const RawLog& log, const ColumnMapping& mapping, long rows, const std::string& time_column) {
  const LogColumn* column = log.find(mapping.column);
  if (column == nullptr)
    map_error(mapping.origin,
              fmt::format("column '{}'{} is not in {}", mapping.column,
                          mapping.pattern.empty() ? "" : fmt::format(" (the pattern {} for '{}')", mapping.pattern, mapping.target),
                          log.file.string()),
              fmt::format("one of its columns: {}", log.column_names()));
  if (!column->unusable.empty())
    throw DataError(log.file, log.location(column->name),
                    fmt::format("mapped to '{}' by {}:{}, but it cannot be used: {}", mapping.target, mapping.origin.file.string(),
                                mapping.origin.location(), column->unusable),
                    "a numeric vector with a finite number for every sample");
  if (rows >= 0 && static_cast<long>(column->values.size()) != rows)
    throw DataError(log.file, log.location(column->name), fmt::format("{} values", column->values.size()),
                    fmt::format("{} values, as many as the time column '{}'", rows, time_column));
  Vector values = Eigen::Map<const Vector>(column->values.data(), static_cast<Eigen::Index>(column->values.size()));
  return mapping.scale * values;
}

/// The position a velocity state is the derivative of: "x" for "x_dot", when "x" is a state.
std::string position_of(const std::string& velocity, const SystemSignature& system) {
  constexpr std::string_view suffix = "_dot";
  if (!velocity.ends_with(suffix)) return "";
  const std::string base = velocity.substr(0, velocity.size() - suffix.size());
  return index_of(system.states, base) >= 0 ? base : "";
}

const ColumnMapping* mapping_for(const std::vector<ColumnMapping>& mappings, const std::string& target) {
  for (const ColumnMapping& m : mappings)
    if (m.target == target) return &m;
  return nullptr;
}

/// Every mapped target is the system's, each state and control has a column or (velocities) an
/// estimator. Returns the estimated velocities as {velocity, position}.
std::vector<std::pair<std::string, std::string>> check_targets(const LogMap& map, const SystemSignature& system) {
  std::set<std::string> seen;
  for (const auto* list : {&map.states, &map.controls}) {
    const bool states = list == &map.states;
    for (const ColumnMapping& m : *list) {
      const auto& names = states ? system.states : system.controls;
      if (index_of(names, m.target) < 0)
        map_error(m.origin, fmt::format("'{}' is not a {} of {}", m.target, states ? "state" : "control", system.name),
                  fmt::format("one of its {}: {}", states ? "states" : "controls", fmt::join(names_of(names), ", ")));
      if (!seen.insert(m.target).second)
        map_error(m.origin, fmt::format("'{}' is mapped twice", m.target), "each state and control mapped once");
    }
  }
  std::vector<std::pair<std::string, std::string>> estimated;
  const MapOrigin& section = map.states_section;
  for (const Quantity& state : system.states) {
    if (mapping_for(map.states, state.name)) continue;
    const std::string position = position_of(state.name, system);
    if (position.empty() || !mapping_for(map.states, position))
      map_error(section, fmt::format("state '{}' has no column", state.name),
                fmt::format("{} = {{ column = \"...\" }} in [states]{}", state.name,
                            position.empty() ? "" : fmt::format(", or '{}' mapped and a [velocities] estimator", position)));
    if (!map.velocities)
      map_error(section, fmt::format("state '{}' has no column and no estimator", state.name),
                fmt::format("{} = {{ column = \"...\" }} in [states], or a [velocities] section to estimate it from '{}'",
                            state.name, position));
    estimated.emplace_back(state.name, position);
  }
  for (const Quantity& control : system.controls)
    if (!mapping_for(map.controls, control.name))
      map_error(map.controls_section, fmt::format("control '{}' has no column", control.name),
                fmt::format("{} = {{ column = \"...\" }} in [controls]", control.name));
  return estimated;
}

/// Rows grouped by episode value, in order of first appearance.
struct RowGroup {
  long episode = 0;
  std::vector<long> rows;
};

std::vector<RowGroup> group_rows(const RawLog& log, const LogMap& map, long rows) {
  std::vector<RowGroup> groups;
  if (!map.episode) {
    groups.push_back({0, {}});
    for (long r = 0; r < rows; ++r) groups[0].rows.push_back(r);
    return groups;
  }
  const Vector ids = mapped_values(log, *map.episode, rows, map.time.column);
  std::map<long, std::size_t> index;
  for (long r = 0; r < rows; ++r) {
    const double v = ids(r) / map.episode->scale;  // episode numbers are not scaled
    if (v != std::round(v) || std::abs(v) > 1e15)
      throw DataError(log.file, log.location(map.episode->column, r), fmt::format("episode value {}", v),
                      "an integer episode number");
    const long id = static_cast<long>(v);
    auto [it, inserted] = index.try_emplace(id, groups.size());
    if (inserted) groups.push_back({id, {}});
    groups[it->second].rows.push_back(r);
  }
  return groups;
}

/// The mapped columns of a log, in SI: the time, and the states and controls in the system's order
/// (empty for a state without a column: an estimated velocity).
struct MappedColumns {
  Vector t;
  std::vector<Vector> states, controls;
  long rows() const { return t.size(); }
};

/// 1. The mapped columns, read and scaled to SI; at least 2 samples, and as many values in every
/// column as in the time column.
MappedColumns read_columns(const RawLog& log, const LogMap& map, const SystemSignature& system, ImportReport& report) {
  MappedColumns columns;
  columns.t = mapped_values(log, map.time, -1, map.time.column);
  const long rows = columns.rows();
  report.rows_read = rows;
  if (rows < 2)
    throw DataError(log.file, log.location(map.time.column), fmt::format("{} sample{}", rows, rows == 1 ? "" : "s"),
                    "at least 2 samples");
  columns.states.resize(system.states.size());
  columns.controls.resize(system.controls.size());
  for (const ColumnMapping& c : map.states)
    columns.states[index_of(system.states, c.target)] = mapped_values(log, c, rows, map.time.column);
  for (const ColumnMapping& c : map.controls)
    columns.controls[index_of(system.controls, c.target)] = mapped_values(log, c, rows, map.time.column);
  return columns;
}

/// The report's used columns (time, episode, states and controls in the system's order) and the
/// log's columns no mapping uses.
void list_columns(const RawLog& log, const LogMap& map, const SystemSignature& system, ImportReport& report) {
  report.columns.push_back(map.time);
  if (map.episode) report.columns.push_back(*map.episode);
  for (const Quantity& q : system.states)
    if (const ColumnMapping* c = mapping_for(map.states, q.name)) report.columns.push_back(*c);
  for (const Quantity& q : system.controls) report.columns.push_back(*mapping_for(map.controls, q.name));
  for (const LogColumn& column : log.columns) {
    const bool used = std::any_of(report.columns.begin(), report.columns.end(),
                                  [&](const ColumnMapping& c) { return log.find(c.column) == &column; });
    if (!used) report.ignored_columns.push_back(column.name);
  }
}

/// 2. The times of every episode, checked to increase strictly within it.
std::vector<Vector> episode_times(const RawLog& log, const LogMap& map, const std::vector<RowGroup>& groups,
                                  const Vector& t_all) {
  std::vector<Vector> group_times;
  for (const RowGroup& g : groups) {
    Vector t(static_cast<Eigen::Index>(g.rows.size()));
    for (std::size_t i = 0; i < g.rows.size(); ++i) {
      t(static_cast<Eigen::Index>(i)) = t_all(g.rows[i]);
      if (i > 0 && !(t(i) > t(i - 1)))
        throw DataError(log.file, log.location(map.time.column, g.rows[i]),
                        fmt::format("time {:.9g} s {} the previous sample's {:.9g} s ({}){}", t(i), t(i) == t(i - 1) ? "repeats" : "is before",
                                    t(i - 1), log.location(map.time.column, g.rows[i - 1]),
                                    map.episode ? fmt::format(" in episode {}", g.episode) : ""),
                        map.episode ? "time to increase strictly within an episode"
                                    : "time to increase strictly (a log of several runs needs an [episode] column)");
    }
    group_times.push_back(std::move(t));
  }
  return group_times;
}

/// 3a. The resampling step dt: the map's, or the median of the log's steps within episodes.
void choose_dt(const RawLog& log, const LogMap& map, const std::vector<Vector>& group_times, ImportReport& report) {
  if (map.dt) {
    report.dt = *map.dt;
    report.dt_from_map = true;
    return;
  }
  std::vector<double> steps;
  for (const Vector& t : group_times)
    for (Eigen::Index i = 1; i < t.size(); ++i) steps.push_back(t(i) - t(i - 1));
  if (steps.empty())
    throw DataError(log.file, log.location(map.time.column), "no episode has 2 samples", "at least 2 samples in an episode");
  std::sort(steps.begin(), steps.end());
  const std::size_t mid = steps.size() / 2;
  report.dt = steps.size() % 2 == 1 ? steps[mid] : 0.5 * (steps[mid - 1] + steps[mid]);
}

/// 3b. The gap limit (the map's max_gap, else 3 dt; at least dt) and every episode split at the steps
/// longer than it (split_at_gaps), with the smallest and largest step left within the pieces, each
/// gap and each record's count of pieces.
std::vector<std::vector<SampleRange>> split_episodes(const LogMap& map, const std::vector<RowGroup>& groups,
                                                     const std::vector<Vector>& group_times, ImportReport& report) {
  report.max_gap_from_map = map.max_gap.has_value();
  report.average_controls = map.average_controls;
  report.max_gap = map.max_gap.value_or(3.0 * report.dt);
  if (report.max_gap < report.dt)
    map_error(map.resample_section,
              fmt::format("max_gap {} s is shorter than dt {} s", report.max_gap, report.dt), "max_gap >= dt");
  std::vector<std::vector<SampleRange>> pieces;
  report.step_min = INFINITY;
  report.step_max = 0.0;
  for (std::size_t g = 0; g < group_times.size(); ++g) {
    const Vector& t = group_times[g];
    pieces.push_back(split_at_gaps(t, report.max_gap));
    report.gaps += static_cast<long>(pieces.back().size()) - 1;
    report.records.push_back({groups[g].episode, t.size(), static_cast<long>(pieces.back().size()), 0});
    for (std::size_t p = 1; p < pieces.back().size(); ++p)
      report.gap_list.push_back({groups[g].episode, t(pieces.back()[p - 1].end - 1), t(pieces.back()[p].begin)});
    for (const SampleRange& r : pieces.back())
      for (long i = r.begin + 1; i < r.end; ++i) {
        report.step_min = std::min(report.step_min, t(i) - t(i - 1));
        report.step_max = std::max(report.step_max, t(i) - t(i - 1));
      }
  }
  if (!std::isfinite(report.step_min)) report.step_min = 0.0;
  return pieces;
}

/// 3c. The resampled length, checked against the sample limit before any grid is allocated (a step
/// of 1e-7 s over a few seconds of log would be gigabytes).
void check_resampled_size(const LogMap& map, const std::vector<Vector>& group_times,
                          const std::vector<std::vector<SampleRange>>& pieces, long rows, const ImportReport& report) {
  double grid_samples = 0.0;
  for (std::size_t g = 0; g < group_times.size(); ++g)
    for (const SampleRange& r : pieces[g])
      grid_samples += uniform_grid_size(group_times[g].segment(r.begin, r.size()), report.dt);
  if (grid_samples > static_cast<double>(limits::kMaxSamples)) {
    MapOrigin origin = map.resample_section;
    origin.field = "resample.dt";
    map_error(origin,
              fmt::format("{} s{} resamples the log's {} rows to {:.0f} samples", report.dt,
                          map.dt ? "" : " (the log's median step)", rows, grid_samples),
              fmt::format("at most {} samples (the sample limit); a larger step", limits::kMaxSamples));
  }
}

/// 4. The velocity estimator of the map's [velocities] section (none when no velocity is estimated),
/// with its noise gains and lag at dt in the report.
std::optional<SavitzkyGolayDerivative> velocity_estimator(ImportReport& report) {
  std::optional<SavitzkyGolayDerivative> differentiator;
  if (!report.estimator) return differentiator;
  try {
    differentiator.emplace(report.estimator->window, report.estimator->order);
  } catch (const std::invalid_argument& e) {
    map_error(report.estimator->origin, e.what(), "an odd window >= 3 and 1 <= order < window");
  }
  report.estimator_noise_gain = differentiator->noise_gain(report.dt);
  report.estimator_end_noise_gain = differentiator->end_noise_gain(report.dt);
  report.estimator_lag = SavitzkyGolayDerivative::lag();
  return differentiator;
}

/// 5-6. One piece (rows `r` of episode `group`, times `t_group`) resampled onto the grid of step dt:
/// states interpolated linearly, estimated velocities differentiated from their positions, controls
/// held (zero order, or averaged over each step with average_controls). Appended as the next episode
/// when the grid has at least `min_samples` samples, else reported as dropped.
void resample_piece(const RowGroup& group, const Vector& t_group, const SampleRange& r, const MappedColumns& columns,
                    const LogMap& map, const SystemSignature& system,
                    const std::optional<SavitzkyGolayDerivative>& differentiator, long min_samples, ImportResult& result) {
  ImportReport& report = result.report;
  const int n = static_cast<int>(system.states.size()), m = static_cast<int>(system.controls.size());
  const Vector t = t_group.segment(r.begin, r.size());
  const Vector tau = uniform_grid(t, report.dt);
  if (tau.size() < min_samples) {
    report.dropped.push_back({group.episode, t(0), t(t.size() - 1), r.size(),
                              fmt::format("{} sample{} at dt = {} s; expected at least {}{}", tau.size(),
                                          tau.size() == 1 ? "" : "s", report.dt, min_samples,
                                          differentiator ? " (the velocity estimator's window)" : "")});
    report.rows_dropped += r.size();
    return;
  }
  auto gather = [&](const Vector& column) {
    Vector v(r.size());
    for (long i = 0; i < r.size(); ++i) v(i) = column(group.rows[static_cast<std::size_t>(r.begin + i)]);
    return v;
  };
  Episode episode;
  episode.id = static_cast<long>(result.set.episodes.size());
  episode.t = tau;
  episode.x.resize(tau.size(), n);
  episode.u.resize(tau.size(), m);
  for (int i = 0; i < n; ++i)
    if (columns.states[i].size() > 0) episode.x.col(i) = interpolate_linear(t, gather(columns.states[i]), tau);
  for (const auto& [velocity, position] : report.estimated)
    episode.x.col(index_of(system.states, velocity)) =
        differentiator->differentiate(episode.x.col(index_of(system.states, position)), report.dt);
  for (int j = 0; j < m; ++j)
    episode.u.col(j) = map.average_controls ? average_held(t, gather(columns.controls[j]), tau, report.dt)
                                            : hold_zero_order(t, gather(columns.controls[j]), tau);
  report.episodes.push_back({episode.id, group.episode, t(0), r.size(), static_cast<long>(tau.size())});
  report.rows_used += r.size();
  report.samples_written += tau.size();
  result.set.episodes.push_back(std::move(episode));
}

}  // namespace

ImportResult import_log(const RawLog& log, const LogMap& written_map, const SystemSignature& system) {
  const LogMap map = expand_patterns(written_map, system);
  ImportResult result;
  ImportReport& report = result.report;
  report.log = log.file;
  report.map = map.file;
  report.format = format_name(log.format);
  report.system = system.name;
  report.estimated = check_targets(map, system);
  report.estimator = report.estimated.empty() ? std::nullopt : map.velocities;

  const MappedColumns columns = read_columns(log, map, system, report);
  const long rows = columns.rows();
  const std::vector<RowGroup> groups = group_rows(log, map, rows);
  list_columns(log, map, system, report);
  const std::vector<Vector> group_times = episode_times(log, map, groups, columns.t);
  choose_dt(log, map, group_times, report);
  const std::vector<std::vector<SampleRange>> pieces = split_episodes(map, groups, group_times, report);
  check_resampled_size(map, group_times, pieces, rows, report);

  const std::optional<SavitzkyGolayDerivative> differentiator = velocity_estimator(report);
  const long min_samples = differentiator ? differentiator->window() : 2;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const std::size_t written_before = result.set.episodes.size();
    for (const SampleRange& r : pieces[g])
      resample_piece(groups[g], group_times[g], r, columns, map, system, differentiator, min_samples, result);
    report.records[g].episodes = static_cast<long>(result.set.episodes.size() - written_before);
  }
  if (result.set.episodes.empty())
    throw DataError(log.file, log.location(map.time.column),
                    fmt::format("no piece of the log is long enough: all {} rows dropped ({} pieces after splitting at "
                                "gaps > {} s)",
                                rows, report.dropped.size(), report.max_gap),
                    fmt::format("an episode of at least {} samples at dt = {} s", min_samples, report.dt));
  result.set.system = system;
  for (const Quantity& state : system.states)  // the provenance, in the system's order
    for (const auto& [velocity, position] : report.estimated)
      if (velocity == state.name) result.set.estimated_states.push_back(velocity);
  return result;
}

}  // namespace gpilqg
