#pragma once
/// @file cli_errors.hpp
/// The command line's error contract (docs/command-line.md#what-every-command-shares;
/// docs/architecture.md#errors): exit 0 on success; exit 2 on bad input (usage, file, data, config)
/// with a message on stderr that starts with "error:" and names the file and the line, field or
/// dataset; exit 1 on an internal failure; exit 128 + signal when a command stopped early on SIGINT or
/// SIGTERM (`gpilqg run`, after saving its progress).

#include <filesystem>
#include <exception>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>

namespace gpilqg {

inline constexpr int kExitSuccess = 0;
inline constexpr int kExitInternalFailure = 1;
inline constexpr int kExitBadInput = 2;
/// A command stopped by a signal at a safe point exits 128 + the signal's number, as a shell reports
/// a process killed by it (130 for SIGINT).
inline constexpr int kExitSignalBase = 128;

/// Bad input found by a command (an option value, a config field). The message names the option
/// or the file and field.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Why solve, plan, rollout and run (the commands that optimise or apply controls) refuse `system`,
/// a system without controls (a passive system: a MuJoCo model without actuators, a URDF whose
/// joints all have effort 0, a plugin with m = 0).
inline std::string passive_system_refusal(const std::string& system) {
  return "system " + system + " has no controls to optimise (a passive system, without actuators); solve, plan, "
         "rollout and run need at least one control. Passive systems work with simulate, data and diagnose";
}

/// An error that another process reports: a rank of an MPI job whose failure rank 0 prints ends
/// with the same exit status and prints nothing, so the message appears once.
class ReportedElsewhere : public std::exception {
 public:
  explicit ReportedElsewhere(int exit_status) : exit_status_(exit_status) {}
  int exit_status() const { return exit_status_; }
  const char* what() const noexcept override { return "an error reported by another process"; }

 private:
  int exit_status_;
};

/// Runs `read`, which reads the input file `file`, and returns what it returns; any failure becomes an
/// InputError naming the file (the message kept as it is when it starts with the file's name, as
/// Hdf5Reader's do): a file that cannot be read as expected is bad input, not an internal failure.
template <typename Read>
auto as_input_error(const std::filesystem::path& file, Read&& read) {
  try {
    return read();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    const std::string what = e.what();
    throw InputError(what.rfind(file.string(), 0) == 0 ? what : file.string() + ": " + what);
  }
}

/// Runs `command` and turns exceptions into the exit-status contract, writing to `err`:
/// DataError, InputError and std::invalid_argument -> "error: <message>", exit 2;
/// a result file the disk refused (AtomicWriteError, FileWriteError: full disk, file-size limit,
/// I/O error) -> "error: <file>: <problem>; the previous file is unchanged", exit 1;
/// ReportedElsewhere -> nothing, its exit status;
/// any other exception -> "internal error: <message>", exit 1.
int run_reporting_errors(const std::function<int()>& command, std::ostream& err);

/// An error as run_reporting_errors reports it, for passing it on (e.g. from one rank of an MPI job
/// to the rank that prints): its exit status, the message as printed ("error: ..." or "internal
/// error: ...", no trailing newline), and the message without a leading "error: ".
struct DescribedError {
  int exit_status = 0;
  std::string message;
  std::string detail;
};
DescribedError describe_error(const std::exception_ptr& error);

}  // namespace gpilqg
