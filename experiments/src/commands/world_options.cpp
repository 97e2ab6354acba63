#include "world_options.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "commands.hpp"

namespace gpilqg::cli {

void add_world_options(CLI::App& cmd, WorldOptions& o) {
  cmd.add_option("--system", o.system, kSystemHelp)->required();
  auto* world = cmd.add_option("--world", o.world_file,
                               "A second MuJoCo model file with the same joints and actuators to simulate instead of --system");
  auto* preset = cmd.add_option("--preset", o.preset, "Parameter set: sim or real")->capture_default_str();
  cmd.add_option("--world-model", o.world_model,
                 "A model file of `diagnose` (--model format: preset, parameters, effects, [[user_effects]]) as the world")
      ->excludes(world)
      ->excludes(preset);
  cmd.add_option("--param", o.parameters, "Override a physical parameter, NAME=VALUE (repeatable)");
  cmd.add_option("--effect", o.effects, "Add a physical effect of the library to the world, EFFECT=VALUE (repeatable)");
  cmd.add_option("--actuator-noise", o.actuator_noise,
                 "Additive actuator noise std [u/sqrt(s)]: one value, or one per control (comma-separated)")
      ->delimiter(',');
  cmd.add_option("--multiplicative-noise", o.multiplicative_noise,
                 "Control-multiplicative noise std [1/sqrt(s)]: one value, or one per control (comma-separated)")
      ->delimiter(',');
}

std::vector<CommandInput> world_inputs(const WorldOptions& o) {
  return {system_input(o.system), {"--world", o.world_file}, {"--world-model", o.world_model}};
}

std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option) {
  std::map<std::string, double> out;
  for (const auto& item : items) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(fmt::format("{} '{}': expected NAME=VALUE, e.g. pole_length=1.3", option, item));
    try {
      std::size_t used = 0;
      const double value = std::stod(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1) throw std::invalid_argument("trailing text");
      if (!std::isfinite(value)) throw std::invalid_argument("not finite");
      out[item.substr(0, eq)] = value;
    } catch (const std::exception&) {
      throw InputError(fmt::format("{} '{}': the value is not a finite number", option, item));
    }
  }
  return out;
}

Vector per_quantity(const std::vector<double>& values, int size, const std::string& option, const Vector& fallback) {
  if (values.empty()) return fallback;
  for (const double v : values)
    if (!(v >= 0.0) || !std::isfinite(v)) throw InputError(fmt::format("{} {}: expected standard deviations >= 0", option, v));
  if (values.size() == 1) return Vector::Constant(size, values.front());
  if (static_cast<int>(values.size()) != size)
    throw InputError(fmt::format("{}: {} values; expected one, or {} (one per entry)", option, values.size(), size));
  return Eigen::Map<const Vector>(values.data(), size);
}

std::string world_setting(const WorldOptions& o) {
  return o.world_model.empty() ? o.preset + " preset" : "model file " + o.world_model;
}

DynamicsPtr build_world(const WorldOptions& o, double* input_delay, const std::string& command) {
  const auto preset = parse_preset(o.preset);
  if (!preset) throw InputError("--preset '" + o.preset + "': expected 'sim' or 'real'");
  const SystemSignature signature = system_signature(o.system);
  const int m = static_cast<int>(signature.controls.size());
  if (m == 0)
    for (const auto& [option, values] : {std::pair{"--actuator-noise", &o.actuator_noise},
                                         std::pair{"--multiplicative-noise", &o.multiplicative_noise}})
      if (!values->empty())
        throw InputError(fmt::format("{}: system {} has no controls (a passive system), so it has no actuator noise; "
                                     "leave the option out",
                                     option, o.system));
  ActuatorNoise noise;
  noise.additive_std = per_quantity(o.actuator_noise, m, "--actuator-noise", Vector());
  noise.multiplicative_std = per_quantity(o.multiplicative_noise, m, "--multiplicative-noise", Vector());
  ModelSpec world;
  world.system = o.system;
  if (!o.world_file.empty()) {
    // Another model file with the same joints and actuators is the world; the data are the system's.
    const std::string mismatch = signature_mismatch(signature, system_signature(o.world_file));
    if (!mismatch.empty()) throw InputError("--world " + o.world_file + ": " + mismatch);
    world.system = o.world_file;
  }
  world.preset = *preset;
  if (!o.world_model.empty()) world = diagnosis::read_model_file(o.world_model, o.system);
  for (const auto& [name, value] : parse_assignments(o.parameters, "--param")) {
    try {
      world = with_parameter(world, name, value);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("--param {}={}: {}", name, value, e.what()));
    }
  }
  for (const std::string& text : o.effects) {
    const diagnosis::EffectRequest request = diagnosis::parse_add_option(text, world, "--effect");
    if (!request.values) throw InputError("--effect '" + text + "': expected EFFECT=VALUE, e.g. cart_coulomb_friction=1");
    world = world.with(find_candidate(world, request.effect), *request.values);
  }
  if (input_delay != nullptr) *input_delay = world.input_delay;
  else if (world.input_delay != 0.0) {
    bool by_effect = false;
    for (const std::string& text : o.effects) by_effect = by_effect || text.rfind("input_delay", 0) == 0;
    throw InputError(fmt::format("{}: an input delay of {} control periods; `gpilqg {}` does not simulate an input delay "
                                 "in closed loop (`gpilqg simulate` does): expected a world without one",
                                 by_effect ? std::string("--effect input_delay") : "--world-model " + o.world_model,
                                 world.input_delay, command));
  }
  return world.build(noise);
}

}  // namespace gpilqg::cli
