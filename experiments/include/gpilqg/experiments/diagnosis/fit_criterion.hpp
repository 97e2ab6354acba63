#pragma once
/// @file fit_criterion.hpp
/// The names of the criteria the candidate effects are fitted to and scored on, as the user and the
/// rule that chooses (criterion_choice.hpp) name them. Each is an object made for its data
/// (criteria/criterion.hpp: one-step, simulation, inverse dynamics) that every step of the diagnosis
/// takes.

#include <optional>
#include <string>
#include <string_view>

namespace gpilqg::diagnosis {

enum class FitCriterion {
  OneStep,          ///< "one-step"
  Simulation,       ///< "simulation", over windows of W samples
  InverseDynamics,  ///< "inverse-dynamics", the generalised-force residual
};

/// "one-step", "simulation" or "inverse-dynamics"; nullopt for any other name.
std::optional<FitCriterion> parse_fit_criterion(std::string_view name);
std::string fit_criterion_name(FitCriterion criterion);

}  // namespace gpilqg::diagnosis
