#pragma once
/// @file config_difference.hpp
/// The first field in which two TOML configs differ, for messages that say what differs instead of
/// "the configs differ": `gpilqg merge` refuses parts run with different configs and names it.
/// Tables are compared key by key in key order, arrays of tables ([[tasks]]) entry by entry; any
/// other value (numbers, strings, arrays of numbers) is compared whole, type included (1 is not 1.0).

#include <optional>
#include <string>

#include <toml++/toml.h>

namespace gpilqg {

struct ConfigDifference {
  std::string field;    ///< the dotted path, with indices for arrays of tables: "gp.backend", "tasks[1].x0"
  std::string value_a;  ///< the value in the first config as TOML text ("\"fitc\"", "[0.0, 0.3]"), or
                        ///< "absent", "a table", "N tables" (an array of tables of another length)
  std::string value_b;  ///< the same for the second config
};

/// std::nullopt when `a` and `b` hold the same fields with the same values.
std::optional<ConfigDifference> config_difference(const toml::table& a, const toml::table& b);

}  // namespace gpilqg
