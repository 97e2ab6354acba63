/// `gpilqg simulate`: synthetic measurements from a system preset under random excitation, with
/// process noise and observation noise, written in the measurement contract (CSV or HDF5).

#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/synthetic_data.hpp"

namespace gpilqg::cli {

namespace {

struct SimulateOptions {
  std::string system;
  std::string preset = "real";
  std::string out;
  std::string world_file;
  std::vector<std::string> parameters;
  std::vector<std::string> effects;
  int episodes = -1;
  int steps = -1;
  double dt = -1.0;
  double actuator_noise = 0.0;
  double multiplicative_noise = 0.0;
  double observation_noise = -1.0;
  std::uint64_t seed = 1;
};

/// "name=value" -> {name, value}; an InputError names the option and the offending text.
std::map<std::string, double> parse_parameters(const std::vector<std::string>& items) {
  std::map<std::string, double> out;
  for (const auto& item : items) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--param '" + item + "': expected NAME=VALUE, e.g. pole_length=1.3");
    try {
      std::size_t used = 0;
      const double value = std::stod(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1) throw std::invalid_argument("trailing text");
      out[item.substr(0, eq)] = value;
    } catch (const std::exception&) {
      throw InputError("--param '" + item + "': the value is not a number");
    }
  }
  return out;
}

int run_simulate(const SimulateOptions& o) {
  const auto preset = parse_preset(o.preset);
  if (!preset) throw InputError("--preset '" + o.preset + "': expected 'sim' or 'real'");
  const auto signature = system_signature(o.system);
  const int n = static_cast<int>(signature.states.size());
  const int m = static_cast<int>(signature.controls.size());

  ActuatorNoise noise;
  if (o.actuator_noise > 0.0) noise.additive_std = Vector::Constant(m, o.actuator_noise);
  if (o.multiplicative_noise > 0.0) noise.multiplicative_std = Vector::Constant(m, o.multiplicative_noise);
  // The world: the preset with overridden parameters and hidden effects of the library.
  ModelSpec world;
  world.system = o.system;
  if (!o.world_file.empty()) {
    // Another model file with the same joints and actuators is the world; the data are the system's.
    const std::string mismatch = signature_mismatch(signature, system_signature(o.world_file));
    if (!mismatch.empty()) throw InputError("--world " + o.world_file + ": " + mismatch);
    world.system = o.world_file;
  }
  world.preset = *preset;
  world.parameters = parse_parameters(o.parameters);
  for (const std::string& text : o.effects) {
    const diagnosis::EffectRequest request = diagnosis::parse_add_option(text, world.system, "--effect");
    if (!request.values) throw InputError("--effect '" + text + "': expected EFFECT=VALUE, e.g. cart_coulomb_friction=1");
    world = world.with(find_effect(world.system, request.effect), *request.values);
  }
  const auto system = world.build(noise);

  ExcitationSettings settings = default_excitation(*system);
  if (o.episodes > 0) settings.episodes = o.episodes;
  if (o.steps > 0) settings.steps = o.steps;
  if (o.dt > 0.0) settings.dt = o.dt;
  if (o.observation_noise >= 0.0) settings.observation_std = Vector::Constant(n, o.observation_noise);
  settings.seed = o.seed;

  SyntheticData data = simulate_measurements(system, settings);
  data.set.system = signature;
  write_measurements(o.out, data.set);
  std::cout << fmt::format("wrote {}: {} {} preset, {} episodes, {} samples, dt = {} s, seed {}\n", o.out,
                           o.system, o.preset, data.set.episodes.size(), data.set.sample_count(),
                           settings.dt, o.seed);
  if (data.truncated_episodes > 0)
    std::cout << fmt::format("note: {} episode(s) diverged and were cut at their last finite sample\n",
                             data.truncated_episodes);
  return kExitSuccess;
}

}  // namespace

void add_simulate_command(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<SimulateOptions>();
  auto* cmd = app.add_subcommand(
      "simulate", "Write synthetic measurements: a system preset under random excitation, with noise");
  cmd->add_option("--system", options->system,
                  kSystemHelp)->required();
  cmd->add_option("--world", options->world_file,
                  "A second MuJoCo model file with the same joints and actuators to simulate instead of --system");
  cmd->add_option("--preset", options->preset, "Parameter set: sim or real")->capture_default_str();
  cmd->add_option("--param", options->parameters, "Override a physical parameter, NAME=VALUE (repeatable)");
  cmd->add_option("--effect", options->effects,
                  "Add a physical effect of the library to the world, EFFECT=VALUE (repeatable)");
  cmd->add_option("--episodes", options->episodes, "Number of episodes (default per system)");
  cmd->add_option("--steps", options->steps, "Samples per episode (default per system)");
  cmd->add_option("--dt", options->dt, "Sampling step in seconds (default 0.02)");
  cmd->add_option("--actuator-noise", options->actuator_noise,
                  "Additive actuator noise std per control [u/sqrt(s)]")->capture_default_str();
  cmd->add_option("--multiplicative-noise", options->multiplicative_noise,
                  "Control-multiplicative noise std [1/sqrt(s)]")->capture_default_str();
  cmd->add_option("--observation-noise", options->observation_noise,
                  "Std of Gaussian noise on each recorded state (default 1e-3)");
  cmd->add_option("--seed", options->seed, "Random seed; the same seed gives the same file")->capture_default_str();
  cmd->add_option("--out", options->out, "Output file (.csv, .h5 or .hdf5)")->required();
  cmd->callback([&action, options] { action = [options] { return run_simulate(*options); }; });
}

}  // namespace gpilqg::cli
