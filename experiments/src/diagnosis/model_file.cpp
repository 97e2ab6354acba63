#include "gpilqg/experiments/diagnosis/model_file.hpp"

#include <cmath>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/toml_fields.hpp"
#include "user_effects_file.hpp"

namespace gpilqg::diagnosis {

namespace {

std::string parameter_names(const LibraryEffect& effect) {
  std::string out;
  for (const auto& p : effect.parameters) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

/// Checks that `values` are acceptable for `effect` in `model`, turning the library's message into
/// `fail(message)`.
template <class Fail>
void check_values(const ModelSpec& model, const LibraryEffect& effect, const Vector& values, Fail&& fail) {
  try {
    static_cast<void>(model.with(effect, values));
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
}

/// A model from its parsed TOML; `file` names the source in errors, `system_origin` what named the
/// system the file must agree with.
ModelSpec read_model_table(const toml::table& root, const std::filesystem::path& file, const std::string& system,
                           const std::string& system_origin) {
  const TomlFields fields(root, file);
  fields.only_keys("", {"model", "parameters", "user_effects", "effects"});
  fields.require_section("model");
  fields.only_keys("model", {"system", "preset"});
  ModelSpec model;
  // The file names the system by its signature name ("cartpole", a MuJoCo model's name), so it stays
  // valid when the model file is given by another path.
  const std::string named = fields.string("model.system");
  if (named != system && named != system_signature(system).name)
    fields.fail("model.system",
                fmt::format("is '{}' but {} is '{}'; expected the same system", named, system_origin, system));
  model.system = system;
  const std::string preset = fields.string("model.preset", std::string("sim"));
  const auto parsed = parse_preset(preset);
  if (!parsed) fields.fail("model.preset", fmt::format("'{}'; expected \"sim\" or \"real\"", preset));
  model.preset = *parsed;

  if (const toml::table* parameters = root["parameters"].as_table()) {
    for (const auto& [key, node] : *parameters) {
      const std::string name(key.str());
      const std::string path = "parameters." + toml_key(name);
      const LibraryEffect* effect = nullptr;
      std::string valid;
      for (const auto& e : effect_library(system)) {
        if (e.kind != EffectKind::Recalibration) continue;
        if (e.recalibrated == name) effect = &e;
        valid += (valid.empty() ? "" : ", ") + e.recalibrated;
      }
      if (effect == nullptr)
        fields.fail(path, fmt::format("unknown parameter '{}' of system '{}'; expected one of: {}", name, system, valid));
      const Vector value = Vector::Constant(1, fields.number(path));
      check_values(model, *effect, value, [&](const std::string& why) { fields.fail(path, why); });
      model = model.with(*effect, value);
    }
  } else if (fields.has("parameters")) {
    fields.fail("parameters", "is not a table; expected [parameters] with name = value entries");
  }
  model.user_effects = read_user_effects(root, file, system);

  if (const toml::table* effects = root["effects"].as_table()) {
    for (const auto& [key, node] : *effects) {
      const std::string name(key.str());
      const std::string path = "effects." + toml_key(name);
      std::optional<LibraryEffect> effect;
      try {
        effect = find_candidate(model, name);
      } catch (const std::invalid_argument&) {
        fields.fail(path, fmt::format("unknown effect '{}'; expected one of: {} (or a name of [[user_effects]])", name,
                                      candidate_names(model)));
      }
      Vector values(static_cast<Eigen::Index>(effect->parameters.size()));
      if (node.is_table()) {
        std::vector<std::string> allowed;
        for (const auto& p : effect->parameters) allowed.push_back(p.name);
        // Coulomb friction's smoothing velocity (the library's default when absent).
        if (effect->smoothing) {
          allowed.push_back("v0");
          if (fields.has(path + ".v0")) {
            const double v0 = fields.number(path + ".v0");
            if (!(v0 > 0.0) || !std::isfinite(v0))
              fields.fail(path + ".v0", fmt::format("is {}; expected a finite smoothing velocity v0 > 0 [{}/s]", v0,
                                                    effect->parameters[0].unit == "N" ? "m" : "rad"));
            effect = with_smoothing(*effect, v0);
          }
        }
        fields.only_keys(path, allowed);
        for (std::size_t i = 0; i < effect->parameters.size(); ++i)
          values(static_cast<Eigen::Index>(i)) = fields.number(path + "." + effect->parameters[i].name);
      } else if (effect->parameters.size() == 1) {
        values(0) = fields.number(path);
      } else {
        fields.fail(path, fmt::format("expected a table of its parameters ({})", parameter_names(*effect)));
      }
      check_values(model, *effect, values, [&](const std::string& why) { fields.fail(path, why); });
      model = model.with(*effect, values);
    }
  } else if (fields.has("effects")) {
    fields.fail("effects", "is not a table; expected [effects] with name = value entries");
  }
  return model;
}

}  // namespace

ModelSpec read_model_file(const std::filesystem::path& file, const std::string& system, const std::string& system_origin) {
  return read_model_table(TomlFields::parse(file), file, system, system_origin);
}

ModelSpec parse_model_text(const std::string& text, const std::string& source, const std::string& system) {
  return read_model_table(TomlFields::parse_text(text, source), source, system, "the system");
}

std::string model_file_text(const ModelSpec& model, const std::vector<std::string>& comment) {
  std::string out;
  for (const auto& line : comment) out += "# " + line + "\n";
  out += fmt::format("[model]\nsystem = \"{}\"\npreset = \"{}\"\n", system_signature(model.system).name,
                     to_string(model.preset));
  if (!model.parameters.empty()) {
    out += "\n[parameters]\n";
    for (const auto& [name, value] : model.parameters) out += fmt::format("{} = {}\n", toml_key(name), value);
  }
  out += user_effects_text(model);
  if (model.actuator_gain != 1.0 || model.input_delay != 0.0 || !model.forces.empty()) {
    out += "\n[effects]\n";
    if (model.actuator_gain != 1.0) out += fmt::format("actuator_gain = {}\n", model.actuator_gain);
    if (model.input_delay != 0.0) out += fmt::format("input_delay = {}   # control periods\n", model.input_delay);
    for (const auto& [name, values] : model.forces) {
      const LibraryEffect effect = find_candidate(model, name);
      std::string table;
      for (std::size_t i = 0; i < effect.parameters.size(); ++i)
        table += fmt::format("{}{} = {}", i == 0 ? "" : ", ", effect.parameters[i].name, values(static_cast<Eigen::Index>(i)));
      if (effect.smoothing) table += fmt::format(", v0 = {}", effect.smoothing->width);
      out += fmt::format("{} = {{ {} }}   # {}\n", toml_key(name), table, effect.formula);
    }
  }
  return out;
}

void write_model_file(const std::filesystem::path& file, const ModelSpec& model, const std::vector<std::string>& comment) {
  write_file_atomically(file, model_file_text(model, comment));
}

EffectRequest parse_add_option(const std::string& text, const std::string& system, const std::string& option) {
  ModelSpec model;
  model.system = system;
  return parse_add_option(text, model, option);
}

EffectRequest parse_add_option(const std::string& text, const ModelSpec& model, const std::string& option) {
  const std::string& system = model.system;
  const auto eq = text.find('=');
  EffectRequest request;
  request.effect = text.substr(0, eq);
  std::optional<LibraryEffect> effect;
  try {
    effect = find_candidate(model, request.effect);
  } catch (const std::invalid_argument&) {
    throw InputError(fmt::format("{} '{}': unknown effect '{}' for system '{}'; expected EFFECT or EFFECT=VALUE with EFFECT one of: {}", option, text, request.effect, system, candidate_names(model)));
  }
  if (eq == std::string::npos) return request;
  const std::string value_text = text.substr(eq + 1);
  if (effect->parameters.size() != 1)
    throw InputError(fmt::format("{} '{}': '{}' has parameters {}; give no value and let the diagnosis fit them", option, text, effect->name, parameter_names(*effect)));
  double value = 0.0;
  try {
    std::size_t used = 0;
    value = std::stod(value_text, &used);
    if (used != value_text.size()) throw std::invalid_argument("trailing text");
  } catch (const std::exception&) {
    throw InputError(fmt::format("{} '{}': '{}' is not a number; expected {}=<{} in {}>", option, text, value_text,
                                 effect->name, effect->parameters[0].name, effect->parameters[0].unit));
  }
  if (!std::isfinite(value))
    throw InputError(fmt::format("{} '{}': the value is not finite; expected a finite number", option, text));
  request.values = Vector::Constant(1, value);
  const ModelSpec& probe = model;
  try {
    static_cast<void>(probe.with(*effect, *request.values));
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{} '{}': {}", option, text, e.what()));
  }
  return request;
}

}  // namespace gpilqg::diagnosis
