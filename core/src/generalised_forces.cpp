#include "gpilqg/core/generalised_forces.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace gpilqg {

std::vector<GeneralisedCoordinate> generalised_coordinates(const Dynamics& system) {
  const auto* forces = dynamic_cast<const GeneralisedForceInput*>(&system);
  if (forces == nullptr) return {};
  std::vector<GeneralisedCoordinate> own = forces->coordinates();
  if (!own.empty()) return own;
  // The convention: "Q_<c>" acts on the states "<c>" and "<c>_dot".
  std::vector<GeneralisedCoordinate> out;
  const auto& components = forces->generalised_forces();
  for (std::size_t k = 0; k < components.size(); ++k) {
    const std::string& force = components[k].name;
    if (force.size() <= 2 || force.compare(0, 2, "Q_") != 0) continue;
    const std::string name = force.substr(2);
    const int position = index_of(system.states(), name);
    const int velocity = index_of(system.states(), name + "_dot");
    if (position < 0 || velocity < 0) continue;
    out.push_back({name, force, static_cast<int>(k), position, velocity});
  }
  return out;
}

GeneralisedCoordinate find_coordinate(const Dynamics& system, std::string_view name) {
  const std::vector<GeneralisedCoordinate> coordinates = generalised_coordinates(system);
  if (coordinates.empty())
    throw std::invalid_argument(fmt::format("unknown coordinate '{}': system '{}' has no generalised coordinates that "
                                            "accept forces (no generalised-force map)",
                                            name, system.name()));
  std::string valid;
  for (const GeneralisedCoordinate& c : coordinates) {
    if (c.name == name || c.force == name) return c;
    valid += fmt::format("{}{} ({})", valid.empty() ? "" : ", ", c.name, c.force);
  }
  throw std::invalid_argument(fmt::format("unknown coordinate '{}' of system '{}'; expected one of: {} (a coordinate "
                                          "or, in parentheses, the force acting on it)",
                                          name, system.name(), valid));
}

}  // namespace gpilqg
