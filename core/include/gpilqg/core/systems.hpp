#pragma once
/// @file systems.hpp
/// Systems by name (docs/formats.md#systems-and-their-names), through the registry of
/// system_registry.hpp, and the paper's two parameter sets: "sim" (the simulator the controller
/// believes) and "real" (the world it acts in). A name is a registered system ("cartpole", "quadrotor",
/// a plugin's) or a MuJoCo model file.

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

/// The registered names: "cartpole", "quadrotor", then those of loaded plugins.
std::vector<std::string> system_names();

/// Builds a system with a preset's parameters, then applies `overrides` by parameter name
/// (e.g. {"pole_length", 1.3}, or {"arm.mass", 1.2} for a MuJoCo model) and attaches the noise model
/// F(x, u). Throws std::invalid_argument listing the valid choices when the system name or a parameter
/// name is unknown, or when a value, a model file or a noise size is invalid.
DynamicsPtr make_system(std::string_view name, Preset preset = Preset::Simulator,
                        const std::map<std::string, double>& overrides = {},
                        const ActuatorNoise& noise = {});

/// The signature (name, states, controls) of a system; throws like make_system.
SystemSignature system_signature(std::string_view name);

/// Empty when `b` has the same states and controls (names, in order) as `a`; otherwise a message
/// listing both sets, e.g. for a "real world" model file that must match the simulator's.
std::string signature_mismatch(const SystemSignature& a, const SystemSignature& b);

}  // namespace gpilqg
