#pragma once
/// @file parameter_checks.hpp
/// Checks of a built-in system's physical parameters, with one message for every system:
///   "<system> parameter '<name>' = <value>; expected <expected>"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg::parameter_checks {

/// Throws std::invalid_argument naming the system, the parameter and its value unless `ok`.
inline void require(bool ok, const char* system, double value, const char* name, const char* expected) {
  if (!ok)
    throw std::invalid_argument(std::string(system) + " parameter '" + name + "' = " + std::to_string(value) +
                                "; expected " + expected);
}

/// value > 0 and finite (masses, lengths, inertias, gravity).
inline void require_positive(const char* system, double value, const char* name) {
  require(std::isfinite(value) && value > 0.0, system, value, name, "a finite value > 0");
}

/// value >= 0 and finite (drag and torque coefficients).
inline void require_non_negative(const char* system, double value, const char* name) {
  require(std::isfinite(value) && value >= 0.0, system, value, name, "a finite value >= 0");
}

}  // namespace gpilqg::parameter_checks
