#pragma once
/// @file atomic_file.hpp
/// Writing a file so that an interrupted or failed write never leaves a half-written result behind
/// (DESIGN.md sections 4 and 7): the content goes to "<file>.tmp-<pid>", which is renamed onto `file`
/// only when the writer returned normally. Used by the measurement writers and the report writers.

#include <filesystem>

namespace gpilqg {

/// The temporary path used by write_atomically: "<file>.tmp-<pid>".
std::filesystem::path temporary_path_for(const std::filesystem::path& file);
/// Renames `temporary` onto `file` (removing `temporary` and throwing DataError naming `file` on failure).
void commit_temporary(const std::filesystem::path& temporary, const std::filesystem::path& file);
/// Removes `temporary` if it exists, ignoring errors (cleanup after a failed write).
void discard_temporary(const std::filesystem::path& temporary) noexcept;

/// `write(temporary)` fills the temporary file, which is then renamed onto `file`; on any exception
/// the temporary file is removed and the exception propagates.
template <class WriteFunction>
void write_atomically(const std::filesystem::path& file, WriteFunction&& write) {
  const std::filesystem::path temporary = temporary_path_for(file);
  try {
    write(temporary);
  } catch (...) {
    discard_temporary(temporary);
    throw;
  }
  commit_temporary(temporary, file);
}

}  // namespace gpilqg
