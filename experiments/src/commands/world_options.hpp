#pragma once
/// @file world_options.hpp
/// The simulated "real world" of `gpilqg simulate` and `gpilqg rollout`, from one set of options: a
/// system's preset with parameter overrides and hidden effects of the library, or a model file of the
/// diagnosis (`--world-model F.toml`, model_file.hpp, with the effects its user declared), or a second
/// MuJoCo model file, with actuator noise. Per-quantity noise options take one value (every entry) or one
/// value per control or state, comma-separated.

#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/quantity.hpp"
#include "output_options.hpp"

namespace gpilqg::cli {

struct WorldOptions {
  std::string system;
  std::string world_file;
  std::string world_model;              ///< a diagnosis model file (model_file.hpp), or empty
  std::string preset = "real";
  std::vector<std::string> parameters;  ///< NAME=VALUE
  std::vector<std::string> effects;     ///< EFFECT=VALUE
  std::vector<double> actuator_noise;        ///< additive std per control [u/sqrt(s)]
  std::vector<double> multiplicative_noise;  ///< std per control [1/sqrt(s)]
};

/// Adds --system, --world, --world-model, --preset, --param, --effect, --actuator-noise and
/// --multiplicative-noise.
void add_world_options(CLI::App& command, WorldOptions& options);

/// The files the world is read from: --system (a model file), --world and --world-model.
std::vector<CommandInput> world_inputs(const WorldOptions& options);

/// "name=value" items of option `option` -> {name: value}; an InputError names the option and the text.
std::map<std::string, double> parse_assignments(const std::vector<std::string>& items, const std::string& option);

/// A per-quantity option: empty -> `fallback`; one value -> that value `size` times; `size` values ->
/// them. Negative entries or another count are an InputError naming the option.
Vector per_quantity(const std::vector<double>& values, int size, const std::string& option, const Vector& fallback);

/// How the world's parameters were chosen, for messages: "real preset" or "model file F.toml".
std::string world_setting(const WorldOptions& options);

/// The world's dynamics with its noise; the signature it must share is `system`'s (checked for --world).
/// `input_delay` receives the world's input delay (--effect input_delay=D, control periods); a command
/// that passes null cannot simulate one, and a delay is then an InputError naming the command.
DynamicsPtr build_world(const WorldOptions& options, double* input_delay = nullptr, const std::string& command = "");

}  // namespace gpilqg::cli
