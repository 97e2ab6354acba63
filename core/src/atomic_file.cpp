/// Atomic file replacement: temporary file in the target's folder, fsync, rename, fsync the folder.

#include "gpilqg/core/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fmt/format.h>
#include <string_view>
#include <system_error>

#include "gpilqg/core/fnv_hash.hpp"

namespace gpilqg {

namespace {

std::string with_reason(const std::string& problem, int error_number) {
  return problem + " (" + std::strerror(error_number) + ")";
}

/// fsync(2) on a file or folder opened read-only (enough on Linux and the BSDs). Returns errno or 0.
int flush_to_disk(const std::filesystem::path& path, bool folder) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (folder ? O_DIRECTORY : 0));
  if (fd < 0) return errno;
  int error = 0;
  while (::fsync(fd) != 0) {
    if (errno == EINTR) continue;
    // Some file systems (and folders on some) do not support fsync; nothing more can be done there.
    if (errno != EINVAL && errno != EROFS) error = errno;
    break;
  }
  ::close(fd);
  return error;
}

void remove_quietly(const std::filesystem::path& file) noexcept {
  std::error_code ignored;
  std::filesystem::remove(file, ignored);
}

void commit(const std::filesystem::path& target, const std::filesystem::path& temporary) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(temporary, error))
    throw AtomicWriteError(target, "the writer did not create the temporary file " + temporary.string() +
                                       "; expected it to write a regular file at the path it was given");
  if (const int e = flush_to_disk(temporary, false); e != 0)
    throw AtomicWriteError(target, with_reason("cannot flush the temporary file " + temporary.string(), e));
  std::filesystem::rename(temporary, target, error);
  if (error)
    throw AtomicWriteError(target, "cannot rename the temporary file " + temporary.string() + " into place (" +
                                       error.message() + "); expected a writable file path");
  // The rename itself is durable only once the folder is flushed; the file is already complete, so
  // a failure here is not reported as a failed write.
  const std::filesystem::path folder = target.has_parent_path() ? target.parent_path() : ".";
  (void)flush_to_disk(folder, true);
}

/// What becomes of the target when a write fails: its previous bytes, or no file at all.
std::string previous_state(const std::filesystem::path& target) {
  std::error_code error;
  return std::filesystem::exists(std::filesystem::symlink_status(target, error))
             ? "the previous file is unchanged"
             : "no file was written";
}

/// The part of a temporary's name before ".tmp-<pid>-<n>": the target's name, or, when the whole
/// temporary name would be too long, its first bytes + "~" + 8 hex digits of its FNV-1a hash.
std::string temporary_stem(const std::string& name) {
  constexpr std::size_t kSuffixRoom = 48;  // ".tmp-" + two 20-digit numbers + "-", rounded up
  if (name.size() + kSuffixRoom <= kMaxFileNameBytes) return name;
  return name.substr(0, kMaxFileNameBytes - kSuffixRoom - 9) + fmt::format("~{:08x}", fnv1a_64(name) & 0xffffffffull);
}

void write_through_temporary(const std::filesystem::path& target, bool copy_existing,
                             const std::function<void(const std::filesystem::path&)>& writer) {
  if (target.empty()) throw AtomicWriteError(target, "empty file name; expected a path to write");
  const std::filesystem::path temporary = atomic_temporary_path(target);
  try {
    if (copy_existing) {
      std::error_code error;
      if (std::filesystem::exists(target, error)) {
        std::filesystem::copy_file(target, temporary, std::filesystem::copy_options::overwrite_existing, error);
        if (error)
          throw AtomicWriteError(target, "cannot copy it to the temporary file " + temporary.string() + " (" +
                                             error.message() + ")");
      }
    }
    writer(temporary);
    commit(target, temporary);
  } catch (const FileWriteError& e) {
    remove_quietly(temporary);
    throw AtomicWriteError(target, "not written: " + e.problem() + " on its temporary file " +
                                       temporary.filename().string() + "; " + previous_state(target));
  } catch (...) {
    remove_quietly(temporary);
    throw;
  }
}

}  // namespace

AtomicWriteError::AtomicWriteError(std::filesystem::path target, std::string problem)
    : std::runtime_error(target.string() + ": " + problem), target_(std::move(target)), problem_(std::move(problem)) {}

FileWriteError::FileWriteError(const std::filesystem::path& file, const std::string& step, int error_number)
    : std::runtime_error(file.string() + ": " + with_reason(step + " failed", error_number)),
      error_number_(error_number),
      problem_(with_reason(step + " failed", error_number)) {}

void write_new_file(const std::filesystem::path& file, std::string_view bytes) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw FileWriteError(file, "creating the file", errno);
  auto fail = [&](const char* step) {
    const int error = errno;
    ::close(fd);
    throw FileWriteError(file, step, error);
  };
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ::ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("writing");
    }
    written += static_cast<std::size_t>(n);
  }
  while (::fsync(fd) != 0) {
    if (errno == EINTR) continue;
    if (errno != EINVAL && errno != EROFS) fail("flushing to the disk (fsync)");
    break;
  }
  if (::close(fd) != 0) throw FileWriteError(file, "closing", errno);
}

void write_file_atomically(const std::filesystem::path& target, std::string_view bytes) {
  write_atomically(target, [&](const std::filesystem::path& temporary) { write_new_file(temporary, bytes); });
}

std::filesystem::path atomic_temporary_path(const std::filesystem::path& target) {
  static std::atomic<unsigned long> counter{0};
  const std::string name = temporary_stem(target.filename().string()) + ".tmp-" +
                           std::to_string(static_cast<long>(::getpid())) + "-" + std::to_string(counter++);
  return target.has_parent_path() ? target.parent_path() / name : std::filesystem::path(name);
}

namespace {

/// The atomic temporaries in `folder` whose names start with `prefix` and whose process has ended
/// (kill(pid, 0) fails with ESRCH; a reused pid keeps a file listed as live, the safe side).
std::vector<std::filesystem::path> stale_temporaries_with(const std::filesystem::path& folder, const std::string& prefix) {
  std::vector<std::filesystem::path> stale;
  std::error_code error;
  for (std::filesystem::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !is_atomic_temporary(it->path())) continue;
    const std::size_t marker = name.rfind(".tmp-") + 5;
    const long pid = std::strtol(name.c_str() + marker, nullptr, 10);
    if (pid <= 0 || pid == static_cast<long>(::getpid())) continue;
    if (::kill(static_cast<::pid_t>(pid), 0) != 0 && errno == ESRCH) stale.push_back(it->path());
  }
  return stale;
}

}  // namespace

std::vector<std::filesystem::path> stale_temporaries(const std::filesystem::path& target) {
  return stale_temporaries_with(target.has_parent_path() ? target.parent_path() : ".",
                                temporary_stem(target.filename().string()) + ".tmp-");
}

std::vector<std::filesystem::path> stale_temporaries_in(const std::filesystem::path& folder) {
  return stale_temporaries_with(folder, "");
}

bool is_atomic_temporary(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  const std::size_t marker = name.rfind(".tmp-");
  if (marker == std::string::npos || marker == 0) return false;
  const std::string_view rest = std::string_view(name).substr(marker + 5);
  const std::size_t dash = rest.find('-');
  if (dash == std::string_view::npos || dash == 0 || dash + 1 == rest.size()) return false;
  auto digits = [](std::string_view s) { return s.find_first_not_of("0123456789") == std::string_view::npos; };
  return digits(rest.substr(0, dash)) && digits(rest.substr(dash + 1));
}

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& temporary)>& writer) {
  write_through_temporary(target, false, writer);
}

void update_atomically(const std::filesystem::path& target,
                       const std::function<void(const std::filesystem::path& temporary)>& writer) {
  write_through_temporary(target, true, writer);
}

}  // namespace gpilqg
