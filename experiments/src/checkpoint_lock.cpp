#include "checkpoint_lock.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

namespace gpilqg {
namespace {

/// The pid the holder wrote into the lock file, or "" when it cannot be read.
std::string holder_of(int fd) {
  char text[32] = {};
  const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
  std::string pid = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : std::string();
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return pid;
}

/// True when `fd` is still the file at `path` (the folder was not removed and made again while the
/// lock was taken).
bool still_there(int fd, const std::filesystem::path& path) {
  struct stat open_file {}, named {};
  return ::fstat(fd, &open_file) == 0 && ::stat(path.c_str(), &named) == 0 && open_file.st_dev == named.st_dev &&
         open_file.st_ino == named.st_ino;
}

}  // namespace

std::shared_ptr<CheckpointLock> CheckpointLock::take(const std::filesystem::path& folder) {
  const std::filesystem::path path = folder / kFileName;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throw std::runtime_error(fmt::format("{}: cannot open the checkpoint's lock file ({})", path.string(),
                                           std::strerror(errno)));
    struct flock lock {};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;
    if (::fcntl(fd, F_OFD_SETLK, &lock) != 0) {
      const int error = errno;
      const std::string pid = holder_of(fd);
      ::close(fd);
      if (error != EAGAIN && error != EACCES)
        throw std::runtime_error(fmt::format("{}: cannot lock the checkpoint ({})", path.string(), std::strerror(error)));
      throw std::invalid_argument(fmt::format("{}: in use by {} (a run or --resume of the same result file is working "
                                              "in it); wait for it to end, or write to another file",
                                              folder.string(), pid.empty() ? "another process" : "pid " + pid));
    }
    if (!still_there(fd, path)) {  // the folder went (a run that finished) between open and lock
      ::close(fd);
      continue;
    }
    const std::string pid = std::to_string(::getpid()) + "\n";
    if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
      // The lock holds without the pid; a second run then names "another process".
    }
    return std::shared_ptr<CheckpointLock>(new CheckpointLock(fd));
  }
  throw std::runtime_error(fmt::format("{}: the checkpoint folder was removed and made again while its lock was taken",
                                       folder.string()));
}

CheckpointLock::~CheckpointLock() { ::close(fd_); }

}  // namespace gpilqg
