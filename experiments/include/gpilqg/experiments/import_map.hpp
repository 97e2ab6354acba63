#pragma once
/// @file import_map.hpp
/// The TOML map of `gpilqg data import` (docs/data-import.md): which log column holds the time, the
/// episode, each state and each control, in which unit, and how to resample and estimate velocities.
///
/// ```toml
/// [time]
/// column = "timestamp"
/// unit = "ms"                      # s (default), ms, us, ns
/// [episode]                        # optional: else one episode (split further at gaps)
/// column = "trial"
/// [resample]                       # optional
/// dt = 0.02                        # [s]; default the median logged step
/// max_gap = 0.1                    # [s]; a longer step starts a new episode; default 3 dt
/// controls = "hold"                # or "average": the control averaged over each step
/// [states]
/// x = { column = "cart_pos_mm", unit = "mm" }
/// theta = { column = "angle_deg", unit = "deg" }
/// [controls]
/// force = "force_N"                # shorthand for { column = "force_N" }, unit SI
/// # "tau{i}" = "effort{i}"         # a pattern: every control tau<number> (map_patterns.hpp)
/// [velocities]                     # estimates x_dot, theta_dot from x, theta when not in [states]
/// method = "savitzky_golay"
/// window = 7
/// order = 2
/// ```

#include <filesystem>

#include "gpilqg/core/log_import.hpp"
#include "gpilqg/core/quantity.hpp"

namespace gpilqg {

/// Reads and checks the map. Throws InputError naming the file, the line and the field for TOML
/// syntax (a key written twice included), unknown sections or keys, a missing [time], [states] or
/// [controls], a missing or non-string column, a unit not in the unit table (units.hpp, listing it),
/// a time unit that is not a time, a non-positive dt or max_gap, max_gap < dt, an unknown velocity
/// method, a window or order out of range, and a malformed pattern (map_patterns.hpp). Entries whose
/// name holds a brace are kept as patterns. Which targets exist, what the patterns match and which
/// columns the log has are checked by import_log, which names the map's line for those too.
LogMap read_import_map(const std::filesystem::path& file);

}  // namespace gpilqg
