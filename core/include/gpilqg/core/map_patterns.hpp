#pragma once
/// @file map_patterns.hpp
/// Patterns of an import map (docs/data-import.md#patterns): one entry that maps many states or
/// controls, for a robot whose joints are numbered. In [states] or [controls],
///
///     "q{i}"     = "pos{i}"                                # q1 <- pos1, q2 <- pos2, ...
///     "q{i}_dot" = { column = "vel{i}", unit = "deg/s" }   # q1_dot <- vel1, ...
///     "tau{i}"   = "effort{i-1}"                           # tau1 <- effort0, ... (0-based log columns)
///
/// - In the target, `{i}` stands for a whole number (one or more digits 0-9) and occurs once; the
///   rest of the target must equal the name literally. "q{i}" matches q1 and q12 but not q1_dot.
/// - In the column, `{i}` is replaced by the same digits as written (q07 <- pos07); `{i+K}` and
///   `{i-K}` (K a whole number) by the number plus or minus K, written without leading zeros. The
///   column must hold at least one placeholder.
/// - An explicit entry of the same section wins over a pattern for its name.
/// - Errors name the map's file, line and field: a pattern that matches no state (control) of the
///   system, a name matched by two patterns, a number that an offset makes negative; a column that
///   the log lacks is reported like an explicit entry's, with the pattern and the name it was
///   expanded for.

#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/log_import.hpp"
#include "gpilqg/core/quantity.hpp"

namespace gpilqg {

/// Why `target` = `column` is not a well-formed pattern (the rules above), or nullopt.
std::optional<std::string> pattern_syntax_problem(const std::string& target, const std::string& column);

/// Whether a map key is meant as a pattern: it holds a brace.
bool is_pattern(const std::string& target);

/// The log column that `pattern` gives the system's name `name`, or nullopt when it does not match.
/// Throws DataError naming the pattern's map line when an offset makes the number negative.
std::optional<std::string> pattern_column(const ColumnMapping& pattern, const std::string& name);

/// `map` with its state and control patterns expanded over the system's names into explicit
/// mappings (each with `pattern` set), after the explicit entries; the patterns are then cleared.
/// Throws DataError naming the map's file, line and field as described above.
LogMap expand_patterns(const LogMap& map, const SystemSignature& system);

}  // namespace gpilqg
