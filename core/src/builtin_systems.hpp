#pragma once
/// The registry entries of the built-in systems (docs/formats.md#systems-and-their-names): cart-pole
/// and quadrotor.

#include <vector>

#include "gpilqg/core/system_registry.hpp"

namespace gpilqg {

/// Both entries, in the order "cartpole", "quadrotor".
std::vector<SystemEntry> builtin_system_entries();

}  // namespace gpilqg
