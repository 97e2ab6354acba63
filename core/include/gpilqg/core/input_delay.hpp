#pragma once
/// @file input_delay.hpp
/// An actuation delay: the input the system applies at sample t is the one commanded d control
/// periods earlier, u_applied(t) = u(t - d), with a fractional d by linear interpolation between
/// samples. With D = floor(d) and f = d - D,
///
///   u_applied(t) = (1 - f) u(t - D) + f u(t - D - 1),
///
/// and a sample index below 0 taken as 0: before the record began, the first recorded command is
/// assumed to have been held (the one assumption a record that starts mid-motion forces).
/// The effect `input_delay` (effect_library.hpp) fits d; `gpilqg simulate --effect input_delay=D`
/// simulates a world with it.

#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// Largest delay the library fits or simulates, in control periods.
inline constexpr double kMaxInputDelay = 50.0;

/// The applied inputs of one episode: `u` holds the commanded inputs, one row per sample (T x m);
/// the result has the same shape. Throws std::invalid_argument for d < 0, d > kMaxInputDelay or d
/// not finite.
Matrix delay_controls(const Matrix& u, double delay);

}  // namespace gpilqg
