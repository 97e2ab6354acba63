#pragma once
/// @file units.hpp
/// The fixed table of units a log's columns may be written in (docs/data-import.md): each unit is a
/// factor to the SI unit of its dimension, value_SI = factor * value. The table knows the dimension of
/// each unit but nothing checks it against the quantity a column is mapped to; an unknown unit is an
/// error, never a guess.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gpilqg {

/// One row of the unit table, e.g. {"deg", "angle", "rad", pi / 180}.
struct UnitScale {
  std::string name;       ///< as written in a map, e.g. "mm/s"
  std::string dimension;  ///< "time", "length", "angle", "velocity", "angular velocity", "force", "torque", ...
  std::string si_unit;    ///< the SI unit the factor converts to, e.g. "m/s"
  double factor = 1.0;    ///< value in si_unit = factor * value in `name`
};

/// The whole table, in the order docs/data-import.md lists it.
const std::vector<UnitScale>& unit_table();

/// The row of `name` (exact, case-sensitive: "mN" and "MN" differ), or std::nullopt.
std::optional<UnitScale> find_unit(std::string_view name);

/// The names of every unit, comma-separated, for "expected one of ..." messages.
std::string unit_names();

}  // namespace gpilqg
