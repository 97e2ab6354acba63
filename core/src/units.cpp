#include "gpilqg/core/units.hpp"

#include <numbers>

namespace gpilqg {

const std::vector<UnitScale>& unit_table() {
  constexpr double deg = std::numbers::pi / 180.0;
  static const std::vector<UnitScale> table = {
      {"s", "time", "s", 1.0},
      {"ms", "time", "s", 1e-3},
      {"us", "time", "s", 1e-6},
      {"ns", "time", "s", 1e-9},
      {"m", "length", "m", 1.0},
      {"cm", "length", "m", 1e-2},
      {"mm", "length", "m", 1e-3},
      {"rad", "angle", "rad", 1.0},
      {"deg", "angle", "rad", deg},
      {"m/s", "velocity", "m/s", 1.0},
      {"cm/s", "velocity", "m/s", 1e-2},
      {"mm/s", "velocity", "m/s", 1e-3},
      {"rad/s", "angular velocity", "rad/s", 1.0},
      {"deg/s", "angular velocity", "rad/s", deg},
      {"rpm", "angular velocity", "rad/s", 2.0 * std::numbers::pi / 60.0},
      {"N", "force", "N", 1.0},
      {"mN", "force", "N", 1e-3},
      {"kN", "force", "N", 1e3},
      {"N m", "torque", "N m", 1.0},
      {"mN m", "torque", "N m", 1e-3},
      {"1", "dimensionless", "1", 1.0},
      {"%", "dimensionless", "1", 1e-2},
  };
  return table;
}

std::optional<UnitScale> find_unit(std::string_view name) {
  for (const UnitScale& unit : unit_table())
    if (unit.name == name) return unit;
  return std::nullopt;
}

std::string unit_names() {
  std::string list;
  for (const UnitScale& unit : unit_table()) list += (list.empty() ? "" : ", ") + unit.name;
  return list;
}

}  // namespace gpilqg
