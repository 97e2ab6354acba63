#pragma once
/// @file elapsed_seconds.hpp
/// Internal: the wall-clock seconds a run reports (solve, fit and prediction times), from the
/// steady clock so that a change of the system time does not show in them.

#include <chrono>

namespace gpilqg {

/// Seconds from `start` to now.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace gpilqg
