#pragma once
/// @file quantity.hpp
/// Named physical quantities: the states, controls and parameters of a system carry a name (fixed by
/// docs/formats.md#systems-and-their-names) and a unit, so data files, reports and error messages can
/// speak of them.

#include <string>
#include <vector>

namespace gpilqg {

/// A named quantity with its SI unit, e.g. {"theta_dot", "rad/s"}.
struct Quantity {
  std::string name;
  std::string unit;
};

/// A named physical parameter of a system with its current value, e.g. {"pole_length", "m", 1.0}.
struct Parameter {
  std::string name;
  std::string unit;
  double value = 0.0;
};

/// What identifies a system's data: its registry name and its states and controls in order.
struct SystemSignature {
  std::string name;
  std::vector<Quantity> states;
  std::vector<Quantity> controls;
};

/// The names (in order) of a list of quantities.
std::vector<std::string> names_of(const std::vector<Quantity>& quantities);

/// Index of `name` in `quantities`, or -1 when absent.
int index_of(const std::vector<Quantity>& quantities, const std::string& name);

}  // namespace gpilqg
