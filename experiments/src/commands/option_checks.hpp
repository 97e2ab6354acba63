#pragma once
/// @file option_checks.hpp
/// Checks of numeric command-line options, attached with CLI11's `->check(...)`: the text must be
/// a whole number (integer_in) or a finite number (number_in) within the range, else the command
/// stops with a usage error (exit 2) naming the option, the value and the range, before any work.
/// No option falls back to a default when given a value outside its range.

#include <limits>

#include <CLI/CLI.hpp>

namespace gpilqg::cli {

/// A whole number in [min, max]: "1e9", "2.5", "-1" (when min >= 0) and "12abc" are refused.
CLI::Validator integer_in(long long min, long long max);

/// A finite number in [min, max] ("nan" and "inf" are refused); with `open_min`, min itself is
/// refused too (e.g. a step that must be > 0).
CLI::Validator number_in(double min, double max, bool open_min = false);

/// A finite number > 0.
inline CLI::Validator positive_number() { return number_in(0.0, std::numeric_limits<double>::max(), true); }

/// A finite number >= 0.
inline CLI::Validator non_negative_number() { return number_in(0.0, std::numeric_limits<double>::max()); }

}  // namespace gpilqg::cli
