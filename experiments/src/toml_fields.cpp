#include "gpilqg/experiments/toml_fields.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/limits.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"

namespace gpilqg {

toml::table TomlFields::parse(const std::filesystem::path& file) {
  check_input_file_as<InputError>(file, kMaxConfigFileBytes, "a TOML config");
  try {
    return toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:line {}: {}; expected valid TOML", file.string(), e.source().begin.line,
                                 e.description()));
  }
}

toml::table TomlFields::parse_text(const std::string& text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:line {}: {}; expected valid TOML", source, e.source().begin.line, e.description()));
  }
}

namespace {

std::string keys_of(const toml::table& table) {
  std::string list;
  for (const auto& [key, node] : table) list += (list.empty() ? "" : ", ") + std::string(key.str());
  return list;
}

/// Fills `overrides` with every entry of `base` it lacks, recursing into tables both have. The
/// user's nodes stay where they were parsed, so they keep their source lines for later errors.
void merge_level(toml::table& overrides, const toml::table& base, const std::string& prefix,
                 const std::vector<std::string>& optional) {
  for (const auto& [key, node] : overrides) {
    const std::string name(key.str());
    const std::string path = prefix.empty() ? name : prefix + "." + name;
    if (base.get(name) == nullptr && std::find(optional.begin(), optional.end(), path) == optional.end()) {
      const auto& source = node.source();
      throw InputError(fmt::format("{}:line {}: unknown field '{}'; expected one of: {}",
                                   source.path ? *source.path : std::string("<config>"), source.begin.line, path,
                                   keys_of(base)));
    }
  }
  for (const auto& [key, node] : base) {
    toml::node* mine = overrides.get(key.str());
    if (mine == nullptr) overrides.insert(key.str(), node);
    else if (mine->is_table() && node.is_table())
      merge_level(*mine->as_table(), *node.as_table(),
                  prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str()), optional);
  }
}

}  // namespace

void TomlFields::merge(toml::table& overrides, const toml::table& base, const std::vector<std::string>& optional) {
  merge_level(overrides, base, "", optional);
}

std::string toml_key(const std::string& key) {
  const bool bare = !key.empty() && key.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
                                        std::string::npos;
  if (bare) return key;
  std::string out = "\"";
  for (const char c : key) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

const toml::node* TomlFields::find(const std::string& path) const {
  if (path.find('"') == std::string::npos) return root_.at_path(path).node();
  // A path with quoted keys (toml_key), e.g. parameters."elbow.damping": walk it segment by segment.
  const toml::node* node = &root_;
  std::size_t i = 0;
  while (i < path.size() && node != nullptr) {
    std::string key;
    if (path[i] == '"') {
      for (++i; i < path.size() && path[i] != '"'; ++i) {
        if (path[i] == '\\' && i + 1 < path.size()) ++i;
        key += path[i];
      }
      ++i;  // the closing quote
    } else {
      while (i < path.size() && path[i] != '.') key += path[i++];
    }
    const toml::table* table = node->as_table();
    node = table == nullptr ? nullptr : table->get(key);
    if (i < path.size() && path[i] == '.') ++i;
  }
  return node;
}

bool TomlFields::has(const std::string& path) const { return find(path) != nullptr; }

std::string TomlFields::source_of(const toml::node* node) const {
  if (node != nullptr && node->source().path && !node->source().path->empty()) return *node->source().path;
  return file_.string();
}

void TomlFields::fail(const std::string& path, const std::string& problem) const {
  const toml::node* node = find(path);
  if (node != nullptr && node->source().begin.line > 0)
    throw InputError(fmt::format("{}:line {}: field '{}': {}", source_of(node), node->source().begin.line, path, problem));
  throw InputError(fmt::format("{}: field '{}': {}", file_.string(), path, problem));
}

void TomlFields::require_section(const std::string& section) const {
  const toml::node* node = find(section);
  if (node == nullptr || !node->is_table())
    throw InputError(fmt::format("{}: missing section [{}]; expected it (see docs/formats.md)", file_.string(), section));
}

void TomlFields::only_keys(const std::string& section, const std::vector<std::string>& allowed) const {
  const toml::table* table = section.empty() ? &root_ : (find(section) ? find(section)->as_table() : nullptr);
  if (table == nullptr) return;
  for (const auto& [key, node] : *table) {
    const std::string name(key.str());
    if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    const std::string path = section.empty() ? name : section + "." + name;
    throw InputError(fmt::format("{}:line {}: unknown field '{}'; expected one of: {}", source_of(&node),
                                 node.source().begin.line, path, list));
  }
}

std::string TomlFields::string(const std::string& path, std::optional<std::string> fallback) const {
  const toml::node* node = find(path);
  if (node == nullptr) {
    if (fallback) return *fallback;
    fail(path, "missing; expected a string");
  }
  if (const auto* s = node->as_string()) return s->get();
  fail(path, "is not a string");
}

bool TomlFields::boolean(const std::string& path, std::optional<bool> fallback) const {
  const toml::node* node = find(path);
  if (node == nullptr) {
    if (fallback) return *fallback;
    fail(path, "missing; expected true or false");
  }
  if (const auto* b = node->as_boolean()) return b->get();
  fail(path, "is not a boolean; expected true or false");
}

double TomlFields::number(const std::string& path, std::optional<double> fallback) const {
  const toml::node* node = find(path);
  if (node == nullptr) {
    if (fallback) return *fallback;
    fail(path, "missing; expected a number");
  }
  double value = 0.0;
  if (const auto* f = node->as_floating_point()) value = f->get();
  else if (const auto* i = node->as_integer()) value = static_cast<double>(i->get());
  else fail(path, "is not a number");
  if (!std::isfinite(value)) fail(path, "is not finite; expected a finite number");
  return value;
}

long TomlFields::integer(const std::string& path, std::optional<long> fallback) const {
  const toml::node* node = find(path);
  if (node == nullptr) {
    if (fallback) return *fallback;
    fail(path, "missing; expected an integer");
  }
  if (const auto* i = node->as_integer()) return static_cast<long>(i->get());
  fail(path, "is not an integer");
}

int TomlFields::integer_in(const std::string& path, int min, int max, std::optional<int> fallback) const {
  const long value = integer(path, fallback);
  if (value < min || value > max) fail(path, fmt::format("is {}; expected an integer from {} to {}", value, min, max));
  return static_cast<int>(value);
}

Vector TomlFields::vector(const std::string& path, int size, std::optional<Vector> fallback) const {
  const toml::node* node = find(path);
  if (node == nullptr) {
    if (fallback) return *fallback;
    fail(path, size >= 0 ? fmt::format("missing; expected an array of {} numbers", size) : "missing; expected an array of numbers");
  }
  const auto* array = node->as_array();
  if (array == nullptr) fail(path, "is not an array");
  if (size >= 0 && static_cast<int>(array->size()) != size)
    fail(path, fmt::format("has {} entries; expected {}", array->size(), size));
  Vector v(static_cast<Eigen::Index>(array->size()));
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& e = (*array)[i];
    if (const auto* f = e.as_floating_point()) v(static_cast<Eigen::Index>(i)) = f->get();
    else if (const auto* n = e.as_integer()) v(static_cast<Eigen::Index>(i)) = static_cast<double>(n->get());
    else fail(path, fmt::format("entry {} is not a number", i));
    if (!std::isfinite(v(static_cast<Eigen::Index>(i)))) fail(path, fmt::format("entry {} is not finite", i));
  }
  return v;
}

void TomlFields::check_bound(const std::string& path, const Vector& v, const char* why) const {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::abs(v(i)) > kDivergedStateMagnitude)
      fail(path, fmt::format("entry {} is {:g}; expected |value| <= {:g} ({})", i, v(i), kDivergedStateMagnitude, why));
}

Vector TomlFields::state_vector(const std::string& path, int size, std::optional<Vector> fallback) const {
  Vector v = vector(path, size, std::move(fallback));
  check_bound(path, v, "beyond it a state counts as diverged");
  return v;
}

Vector TomlFields::control_vector(const std::string& path, int size, std::optional<Vector> fallback) const {
  Vector v = vector(path, size, std::move(fallback));
  check_bound(path, v, "beyond it a control drives every model past the divergence bound");
  return v;
}

Vector TomlFields::weight_vector(const std::string& path, int size, std::optional<Vector> fallback) const {
  Vector v = vector(path, size, std::move(fallback));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (v(i) < 0.0) fail(path, fmt::format("has negative entries (entry {} is {:g}); expected weights >= 0", i, v(i)));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (v(i) > limits::kMaxCostWeight)
      fail(path, fmt::format("entry {} is {:g}; expected a weight in [0, {:g}] (a larger one makes the cost of states "
                             "within the divergence bound overflow)",
                             i, v(i), limits::kMaxCostWeight));
  return v;
}

std::filesystem::path TomlFields::file_path(const std::string& path) const {
  const std::filesystem::path named = string(path);
  if (named.is_relative()) return (std::filesystem::path(source_of(find(path))).parent_path() / named).lexically_normal();
  return named;
}

std::string TomlFields::system_name(const std::string& path) const {
  std::string name = string(path);
  if (is_model_file_name(name)) name = file_path(path).string();
  try {
    (void)find_system(name);
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
  return name;
}

SystemSignature TomlFields::system(const std::string& path) const {
  const std::string name = system_name(path);
  try {
    return system_signature(name);
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
}

bool TomlFields::own_integrator(const std::string& system_name, const std::string& integrator_path,
                                const std::string& substeps_path) const {
  if (gpilqg::own_integrator(*make_system(system_name)) == nullptr) return false;
  for (const std::string& field : {integrator_path, substeps_path})
    if (has(field))
      fail(field, "not used: the system's own integrator and timestep are its simulator (a MuJoCo model's "
                  "<option integrator=... timestep=...>); remove this field");
  return true;
}

Integrator TomlFields::integrator(const std::string& path, std::optional<std::string> fallback) const {
  const std::string name = string(path, std::move(fallback));
  if (auto i = parse_integrator(name)) return *i;
  fail(path, fmt::format("'{}'; expected \"euler\" or \"rk4\"", name));
}

}  // namespace gpilqg
