#pragma once
/// @file atomic_file.hpp
/// Writing result files so that a reader never sees a half-written file and a failure never loses
/// the previous one (docs/reliability.md#atomic-writes).
///
/// The protocol of write_atomically(target, writer):
///  1. `writer(temporary)` creates and fills a fresh file in target's own folder (same file system,
///     so the rename below is atomic), named "<target>.tmp-<pid>-<n>" (atomic_temporary_path).
///  2. The temporary file's data is flushed to the disk (fsync), so that the rename can never
///     expose a file whose blocks are not yet written after a power loss.
///  3. std::filesystem::rename moves it onto `target` in one step (POSIX rename(2) replaces an
///     existing file atomically), and the folder is flushed so that the new name persists.
/// When `writer` throws, or any step fails, the temporary file is removed and `target` is left
/// exactly as it was (absent, or byte for byte the previous file). An interrupted process (SIGKILL,
/// power loss) can leave a "<target>.tmp-<pid>-<n>" file behind, never a partial `target`.
///
/// update_atomically(target, writer) is the same for writers that modify an existing file (e.g.
/// adding a group to an HDF5 file): the temporary starts as a copy of `target` when it exists.

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace gpilqg {

/// The longest file name the usual file systems accept (NAME_MAX on Linux: ext4, tmpfs, XFS, btrfs).
inline constexpr std::size_t kMaxFileNameBytes = 255;

/// A failure of the atomic-write machinery itself (temporary not created, flush or rename failed).
/// what() reads "<target>: <problem> (<system reason>)"; target() is the file that was being written.
class AtomicWriteError : public std::runtime_error {
 public:
  AtomicWriteError(std::filesystem::path target, std::string problem);
  const std::filesystem::path& target() const { return target_; }
  /// what() without the leading "<target>: ".
  const std::string& problem() const { return problem_; }

 private:
  std::filesystem::path target_;
  std::string problem_;
};

/// A write(2), fsync(2) or close(2) that failed on a file being written (a full disk, a file-size
/// limit, an I/O error). write_atomically turns it into an AtomicWriteError that names the target.
class FileWriteError : public std::runtime_error {
 public:
  FileWriteError(const std::filesystem::path& file, const std::string& step, int error_number);
  /// The errno of the failed call.
  int error_number() const { return error_number_; }
  /// "<step> failed (<strerror>)", without the file name.
  const std::string& problem() const { return problem_; }

 private:
  int error_number_;
  std::string problem_;
};

/// Fills "<target>.tmp-<pid>-<n>" through `writer` and renames it onto `target` (see the file
/// comment). `writer` must create the file at the path it is given (it does not exist beforehand).
/// Exceptions of `writer` propagate unchanged after the temporary file is removed; a temporary that
/// `writer` did not create, a failed fsync or a failed rename (e.g. `target` is a folder) throw
/// AtomicWriteError. A symbolic link at `target` is replaced by the new file, not written through.
/// Thread-safe: concurrent calls get distinct temporary names (the last rename wins).
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& writer);

/// As write_atomically, but the temporary file is first a copy of `target` when `target` exists
/// (otherwise it does not exist when `writer` runs), so that `writer` can modify the previous
/// contents; a failed copy throws AtomicWriteError and leaves `target` untouched.
void update_atomically(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path& temporary)>& writer);

/// Creates `file` (it must not exist) and writes `bytes` to it with every write(2) checked, then
/// fsync(2) and close(2), both checked: the one place where result bytes meet the disk. Throws
/// FileWriteError naming the failed step and the OS error; a partly written file is left for the
/// caller (write_atomically removes its temporary).
void write_new_file(const std::filesystem::path& file, std::string_view bytes);

/// write_atomically with write_new_file: the whole of `bytes` replaces `target`, or nothing changes.
void write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

/// A fresh temporary name beside `target`: "<target>.tmp-<pid>-<n>" with n counting up per process.
/// When that name would exceed the file system's limit of 255 bytes per name, the target's name is
/// shortened to its first bytes plus "~" and 8 hex digits of a hash of the whole name, so that a
/// legal target name always has a legal temporary name.
std::filesystem::path atomic_temporary_path(const std::filesystem::path& target);

/// Temporary files of `target` (named as atomic_temporary_path names them) whose process no longer
/// runs: the leftovers of an interrupted write (SIGKILL, power loss). Files of running processes,
/// including this one, are not listed.
std::vector<std::filesystem::path> stale_temporaries(const std::filesystem::path& target);

/// The same for every atomic temporary in `folder` (e.g. a checkpoint folder).
std::vector<std::filesystem::path> stale_temporaries_in(const std::filesystem::path& folder);

/// True when `file`'s name has the form "<name>.tmp-<digits>-<digits>" (a leftover temporary of an
/// interrupted atomic write), for clean-up tools.
bool is_atomic_temporary(const std::filesystem::path& file);

}  // namespace gpilqg
