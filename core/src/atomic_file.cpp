/// Atomic file replacement: temporary file in the target's folder, fsync, rename, fsync the folder.

#include "gpilqg/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string_view>
#include <system_error>

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
  } catch (...) {
    remove_quietly(temporary);
    throw;
  }
}

}  // namespace

AtomicWriteError::AtomicWriteError(std::filesystem::path target, std::string problem)
    : std::runtime_error(target.string() + ": " + problem), target_(std::move(target)), problem_(std::move(problem)) {}

std::filesystem::path atomic_temporary_path(const std::filesystem::path& target) {
  static std::atomic<unsigned long> counter{0};
  std::filesystem::path temporary = target;
  temporary += ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" + std::to_string(counter++);
  return temporary;
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
