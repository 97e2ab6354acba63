#pragma once
/// @file input_file.hpp
/// The check every reader makes before it opens an input file: the path must name a regular file
/// (after following symbolic links), readable, and no larger than a limit, so that a FIFO given as a
/// data file cannot block the program (opening a FIFO waits for a writer), /dev/zero cannot fill the
/// memory, and a loop of symbolic links is not reported as a missing file.
///
/// Nothing is opened: the check uses stat(2) and access(2) only. Messages read
/// "<file>: <problem>; expected <description>", e.g.
///   "data.csv: is a FIFO (named pipe), not a regular file; expected a measurement file".

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace gpilqg {

/// The largest data file a reader accepts: measurement sets, raw logs, benchmark sets and every
/// HDF5 file the program reads (results, policies, checkpoints, saved GPs). 4 GiB.
inline constexpr std::uintmax_t kMaxDataFileBytes = std::uintmax_t{4} << 30;

/// The largest text config a reader accepts: TOML configs (solve, plan, run), import maps, model
/// files of `gpilqg diagnose`, MuJoCo models. 16 MiB.
inline constexpr std::uintmax_t kMaxConfigFileBytes = std::uintmax_t{16} << 20;

/// How messages name the kind of a file-system entry: "a regular file", "a folder", "a FIFO (named
/// pipe)", "a socket", "a character device", "a block device", "a symbolic link", "a special file".
const char* file_kind(std::filesystem::file_type type);

/// Why a path cannot be read as an input file.
struct InputFileIssue {
  std::string problem;   ///< e.g. "no such file", "is a folder, not a regular file"
  std::string expected;  ///< what the reader needs, e.g. "a measurement file"
  /// "<file>: <problem>; expected <expected>".
  std::string message(const std::filesystem::path& file) const;
};

/// Checks `file` without opening it. `description` names what the reader expects, with its article
/// ("a measurement file", "an HDF5 file"). Problems, in the order they are found:
///  - the path cannot be resolved: "no such file", "too many levels of symbolic links (a loop of
///    symbolic links)", "a component of the path is not a folder", or the system's reason;
///  - it is not a regular file: "is a folder", "is a FIFO (named pipe)", "is a socket",
///    "is a character device", "is a block device" (each followed by ", not a regular file");
///  - it is not readable by this user;
///  - it is larger than `max_bytes` (the expected text then states the limit).
/// Returns the first problem, or nullopt when the file can be read; then `bytes`, when given,
/// receives the file's size.
std::optional<InputFileIssue> input_file_issue(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                               std::string_view description, std::uintmax_t* bytes = nullptr);

/// input_file_issue for the data readers: throws DataError (measurements.hpp) with the file and an
/// empty location when there is a problem. Returns the file's size in bytes (what the HDF5 readers
/// compare declared dataset sizes with, dataset_size.hpp).
std::uintmax_t check_input_file(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                std::string_view description);

/// input_file_issue for readers with an exception type of their own (e.g. InputError of the
/// command line, std::invalid_argument): throws `Error(issue->message(file))`. Returns the size.
template <class Error>
std::uintmax_t check_input_file_as(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                   std::string_view description) {
  std::uintmax_t bytes = 0;
  if (const auto issue = input_file_issue(file, max_bytes, description, &bytes)) throw Error(issue->message(file));
  return bytes;
}

}  // namespace gpilqg
