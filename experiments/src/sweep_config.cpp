#include "gpilqg/experiments/sweep_config.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {
namespace {

/// One step of a field's path: a key, and an array index when the step was written "key[i]".
struct PathStep {
  std::string key;
  int index = -1;
};

/// "tasks[1].horizon" -> {tasks, 1}, {horizon}; keys may be quoted ("world.parameters.\"a.b\"").
std::vector<PathStep> split_path(const std::string& path) {
  std::vector<PathStep> steps(1);
  bool quoted = false;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '"') {
      quoted = !quoted;
    } else if (!quoted && c == '.') {
      steps.emplace_back();
    } else if (!quoted && c == '[') {
      // One index per step, digits only, then '.' or the end: "tasks[1].horizon".
      const std::size_t close = path.find(']', i);
      if (close == std::string::npos || close == i + 1 || steps.back().index >= 0) return {};
      const std::string digits = path.substr(i + 1, close - i - 1);
      if (digits.size() > 6 || !std::all_of(digits.begin(), digits.end(), [](char d) { return d >= '0' && d <= '9'; }))
        return {};
      if (close + 1 < path.size() && path[close + 1] != '.') return {};
      steps.back().index = std::stoi(digits);
      i = close;
    } else if (!quoted && (c == ']' || steps.back().index >= 0)) {
      return {};  // text after an index within one step
    } else {
      steps.back().key += c;
    }
  }
  for (const auto& s : steps)
    if (s.key.empty()) return {};
  return steps;
}

/// The node at `path` in `root`, or null.
toml::node* find_node(toml::table& root, const std::vector<PathStep>& steps) {
  toml::node* node = &root;
  for (const auto& step : steps) {
    toml::table* table = node->as_table();
    if (table == nullptr) return nullptr;
    node = table->get(step.key);
    if (node == nullptr) return nullptr;
    if (step.index >= 0) {
      toml::array* array = node->as_array();
      if (array == nullptr || step.index >= static_cast<int>(array->size())) return nullptr;
      node = array->get(static_cast<std::size_t>(step.index));
    }
  }
  return node;
}

/// Replaces the node at `steps` (which exists) by a copy of `value`.
void replace_node(toml::table& root, const std::vector<PathStep>& steps, const toml::node& value) {
  std::vector<PathStep> parent_steps(steps.begin(), steps.end() - 1);
  PathStep last = steps.back();
  toml::node* parent = parent_steps.empty() ? &root : find_node(root, parent_steps);
  toml::table& table = *parent->as_table();
  value.visit([&](const auto& v) {
    if (last.index < 0)
      table.insert_or_assign(last.key, v);
    else
      table.get(last.key)->as_array()->replace(table.get(last.key)->as_array()->begin() + last.index, v);
  });
}

std::string value_text(const toml::node& node) {
  std::ostringstream out;
  node.visit([&](const auto& v) { out << v; });
  return out.str();
}

}  // namespace

std::string SweepPoint::label() const {
  std::string out;
  for (const auto& [field, value] : values) out += fmt::format("{}{} = {}", out.empty() ? "" : ", ", field, value);
  return out;
}

SweepConfig load_sweep_config(const std::filesystem::path& file) {
  toml::table root = TomlFields::parse(file);
  const TomlFields f(root, file);
  f.only_keys("", {"system", "config", "seeds", "first_seed", "iterations", "out", "grid"});
  f.require_section("grid");
  SweepConfig s;
  s.file = file;
  {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    s.text = text.str();
  }
  const std::filesystem::path folder = file.parent_path();
  s.system = f.system_name("system");
  const int seeds = f.integer_in("seeds", 1, limits::kMaxSeeds, 1);
  const long first_seed = f.integer("first_seed", 1);
  if (first_seed < 0 || static_cast<std::uint64_t>(first_seed) + static_cast<std::uint64_t>(seeds) - 1 > limits::kMaxSeed)
    f.fail("first_seed", fmt::format("{} with {} seeds; expected seeds within [0, {}]", first_seed, seeds, limits::kMaxSeed));
  for (int i = 0; i < seeds; ++i) s.seeds.push_back(static_cast<std::uint64_t>(first_seed) + static_cast<std::uint64_t>(i));
  std::optional<int> iterations;
  if (f.has("iterations")) iterations = f.integer_in("iterations", 1, limits::kMaxLoopIterations);
  s.out = f.has("out") ? folder / f.string("out") : folder / (file.stem().string() + ".h5");

  std::optional<std::filesystem::path> base_file;
  if (f.has("config")) base_file = folder / f.string("config");
  if (base_file) s.config = *base_file;
  const RunConfig base = load_run_config(s.system, base_file);
  toml::table effective = TomlFields::parse_text(base.text, "<the effective run config>");

  // The grid's fields in the order they are written.
  const toml::table& grid = *root["grid"].as_table();
  std::vector<std::pair<std::string, const toml::array*>> entries;
  std::vector<std::pair<toml::source_position, std::size_t>> order;
  for (const auto& [key, node] : grid) {
    const std::string field(key.str());
    const std::string where = "grid." + toml_key(field);
    if (split_path(field).empty() || find_node(effective, split_path(field)) == nullptr)
      f.fail(where, fmt::format("'{}' is not a field of the run config of {} (e.g. \"loop.rollouts\", \"gp.backend\", "
                                "\"tasks[1].horizon\")", field, s.system));
    const toml::array* values = node.as_array();
    if (values == nullptr || values->empty()) f.fail(where, "expected a non-empty array of the values to try");
    for (const auto& value : *values)
      if (value.is_table())
        f.fail(where, "a value is a table; vary the table's fields one by one (e.g. \"world.parameters.pole_mass\")");
    if (f.has("iterations") && field == "loop.iterations")
      f.fail(where, "the sweep file's `iterations` would override every value of this field; remove one of them");
    order.emplace_back(key.source().begin, entries.size());
    entries.emplace_back(field, values);
  }
  if (entries.empty()) f.fail("grid", "expected at least one field to vary");
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    return a.first.line != b.first.line ? a.first.line < b.first.line : a.first.column < b.first.column;
  });
  std::vector<std::pair<std::string, const toml::array*>> fields;
  for (const auto& [position, i] : order) fields.push_back(entries[i]), s.fields.push_back(entries[i].first);

  long long count = 1;
  for (const auto& [field, values] : fields) {
    count *= static_cast<long long>(values->size());
    if (count > kMaxSweepPoints) f.fail("grid", fmt::format("more than {} grid points", kMaxSweepPoints));
  }
  for (long long p = 0; p < count; ++p) {
    SweepPoint point;
    toml::table table = effective;
    long long rest = p;
    std::vector<std::size_t> choice(fields.size());
    for (std::size_t i = fields.size(); i-- > 0;) {
      const auto n = static_cast<long long>(fields[i].second->size());
      choice[i] = static_cast<std::size_t>(rest % n);
      rest /= n;
    }
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const toml::node& value = *fields[i].second->get(choice[i]);
      replace_node(table, split_path(fields[i].first), value);
      point.values.emplace_back(fields[i].first, value_text(value));
    }
    std::ostringstream text;
    text << toml::toml_formatter{table};
    try {
      point.config = parse_run_config(s.system, text.str(), fmt::format("grid point {}", p));
      if (iterations) point.config = with_iterations(std::move(point.config), *iterations, "field 'iterations'");
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: grid point {} ({}): {}", file.string(), p, point.label(), e.what()));
    }
    s.points.push_back(std::move(point));
  }
  return s;
}

}  // namespace gpilqg
