#include "gpilqg/experiments/import_map.hpp"

#include <algorithm>
#include <fmt/format.h>

#include "gpilqg/core/map_patterns.hpp"
#include "gpilqg/core/units.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {

namespace {

long line_of(const toml::node* node) { return node != nullptr ? static_cast<long>(node->source().begin.line) : 0; }

/// The entry at `path` (a table {column, unit} or a column name): its column and unit scale.
ColumnMapping read_mapping(const TomlFields& fields, const toml::node* node, const std::filesystem::path& file,
                           const std::string& path, const std::string& target, bool allow_unit) {
  ColumnMapping mapping;
  mapping.target = target;
  if (node != nullptr && node->is_string()) {
    mapping.column = node->as_string()->get();
    mapping.origin = {file, line_of(node), path};
  } else {
    if (node == nullptr || !node->is_table())
      fields.fail(path, "expected a table { column = \"...\", unit = \"...\" } or a column name");
    fields.only_keys(path, allow_unit ? std::vector<std::string>{"column", "unit"} : std::vector<std::string>{"column"});
    mapping.column = fields.string(path + ".column");
    mapping.origin = {file, line_of(node->as_table()->get("column")), path + ".column"};
    if (allow_unit && fields.has(path + ".unit")) {
      mapping.unit = fields.string(path + ".unit");
      const auto unit = find_unit(mapping.unit);
      if (!unit) fields.fail(path + ".unit", fmt::format("unknown unit '{}'; expected one of: {}", mapping.unit, unit_names()));
      mapping.scale = unit->factor;
    }
  }
  if (mapping.column.empty()) fields.fail(path, "an empty column name; expected the log's name for the column");
  return mapping;
}

MapOrigin section_origin(const toml::table& root, const std::filesystem::path& file, const std::string& section) {
  return {file, line_of(root.get(section)), section};
}

}  // namespace

LogMap read_import_map(const std::filesystem::path& file) {
  const toml::table root = TomlFields::parse(file);
  const TomlFields fields(root, file);
  fields.only_keys("", {"time", "episode", "resample", "states", "controls", "velocities"});
  // [controls] may be left out for a system without controls (a passive system); for any other
  // system each control's missing column is then an error naming it (log_import.cpp).
  for (const char* section : {"time", "states"}) fields.require_section(section);

  LogMap map;
  map.file = file;
  fields.only_keys("time", {"column", "unit"});
  map.time = read_mapping(fields, root.get("time"), file, "time", "time", true);
  if (!map.time.unit.empty() && find_unit(map.time.unit)->dimension != "time")
    fields.fail("time.unit", fmt::format("'{}' is not a unit of time; expected s, ms, us or ns", map.time.unit));
  if (fields.has("episode")) {
    fields.only_keys("episode", {"column"});
    map.episode = read_mapping(fields, root.get("episode"), file, "episode", "episode", false);
  }

  map.resample_section = section_origin(root, file, "resample");
  if (fields.has("resample")) {
    fields.only_keys("resample", {"dt", "max_gap", "controls"});
    const std::string controls = fields.string("resample.controls", "hold");
    if (controls != "hold" && controls != "average")
      fields.fail("resample.controls", fmt::format("unknown rule '{}'; expected \"hold\" or \"average\"", controls));
    map.average_controls = controls == "average";
    if (fields.has("resample.dt")) {
      map.dt = fields.number("resample.dt");
      if (!(*map.dt > 0.0)) fields.fail("resample.dt", fmt::format("{} s; expected a positive step", *map.dt));
    }
    if (fields.has("resample.max_gap")) {
      map.max_gap = fields.number("resample.max_gap");
      if (!(*map.max_gap > 0.0)) fields.fail("resample.max_gap", fmt::format("{} s; expected a positive time", *map.max_gap));
      if (map.dt && *map.max_gap < *map.dt)
        fields.fail("resample.max_gap", fmt::format("{} s is shorter than dt = {} s; expected max_gap >= dt", *map.max_gap, *map.dt));
    }
  }

  for (const char* section : {"states", "controls"}) {
    if (root.get(section) == nullptr) continue;  // no [controls]
    if (!root.get(section)->is_table())
      fields.fail(section, fmt::format("expected a table [{}] of NAME = \"column\" entries", section));
    const toml::table* table = root.get(section)->as_table();
    const bool states = std::string(section) == "states";
    for (const auto& [key, node] : *table) {
      const std::string target(key.str());
      const std::string path = std::string(section) + "." + toml_key(target);
      ColumnMapping mapping = read_mapping(fields, &node, file, path, target, true);
      if (!is_pattern(target)) {
        (states ? map.states : map.controls).push_back(std::move(mapping));
        continue;
      }
      mapping.origin.field = path;  // errors about a pattern name its entry
      mapping.origin.line = line_of(&node);
      if (const auto problem = pattern_syntax_problem(target, mapping.column))
        fields.fail(path, fmt::format("{}; expected a pattern such as \"q{{i}}\" = \"pos{{i}}\" ({{i}}: a whole number; "
                                      "{{i+K}} or {{i-K}} in the column shift it by K)",
                                      *problem));
      (states ? map.state_patterns : map.control_patterns).push_back(std::move(mapping));
    }
  }
  map.states_section = section_origin(root, file, "states");
  map.controls_section = section_origin(root, file, "controls");

  if (fields.has("velocities")) {
    fields.only_keys("velocities", {"method", "window", "order"});
    const std::string method = fields.string("velocities.method");
    if (method != "savitzky_golay")
      fields.fail("velocities.method", fmt::format("unknown method '{}'; expected \"savitzky_golay\"", method));
    VelocityEstimator estimator;  // its members hold the defaults
    estimator.window = fields.integer_in("velocities.window", 3, 1001, estimator.window);
    if (estimator.window % 2 == 0)
      fields.fail("velocities.window", fmt::format("{} is even; expected an odd number of samples", estimator.window));
    estimator.order = fields.integer_in("velocities.order", 1, estimator.window - 1, std::min(estimator.order, estimator.window - 1));
    estimator.origin = section_origin(root, file, "velocities");
    map.velocities = estimator;
  }
  return map;
}

}  // namespace gpilqg
