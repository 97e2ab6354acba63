#pragma once
/// @file stop_signal.hpp
/// Ctrl-C for long commands: while a StopSignalGuard lives, the first SIGINT or SIGTERM only asks the
/// command to stop at its next safe point (stop_requested() turns true, and a line on stderr says so);
/// a second one ends the process at once with the default action. The previous handlers come back
/// when the guard is destroyed.

namespace gpilqg::cli {

class StopSignalGuard {
 public:
  StopSignalGuard();
  ~StopSignalGuard();
  StopSignalGuard(const StopSignalGuard&) = delete;
  StopSignalGuard& operator=(const StopSignalGuard&) = delete;

  /// True once SIGINT or SIGTERM has arrived (async-signal-safe flag).
  static bool stop_requested();
  /// The signal that asked to stop (0: none).
  static int signal_number();
  /// The exit status of a command that stopped early: 128 + the signal (SIGTERM when the stop came
  /// from elsewhere, e.g. another rank of an MPI job).
  static int exit_status();
};

}  // namespace gpilqg::cli
