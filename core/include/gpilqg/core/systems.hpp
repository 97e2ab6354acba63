#pragma once
/// @file systems.hpp
/// The registry of built-in systems by their fixed names (DESIGN.md section 3) and the paper's two
/// parameter sets: "sim" (the simulator the controller believes) and "real" (the world it acts in).

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/dynamics.hpp"

namespace gpilqg {

enum class Preset { Simulator, RealWorld };

/// "sim" or "real"; std::nullopt otherwise.
std::optional<Preset> parse_preset(std::string_view name);
std::string_view to_string(Preset preset);

/// The names of all built-in systems: "cartpole", "quadrotor".
const std::vector<std::string>& system_names();

/// Builds a system with a preset's parameters, then applies `overrides` by parameter name
/// (e.g. {"pole_length", 1.3}) and attaches the noise model F(x, u). Throws std::invalid_argument
/// listing the valid choices when the system name or a parameter name is unknown, or when a value
/// or a noise size is invalid.
DynamicsPtr make_system(std::string_view name, Preset preset = Preset::Simulator,
                        const std::map<std::string, double>& overrides = {},
                        const ActuatorNoise& noise = {});

/// The signature (name, states, controls) of a built-in system; throws like make_system.
SystemSignature system_signature(std::string_view name);

}  // namespace gpilqg
