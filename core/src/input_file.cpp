/// The check of an input file before it is opened (input_file.hpp): stat(2) follows symbolic links
/// and never blocks, unlike open(2) on a FIFO.

#include "gpilqg/core/input_file.hpp"

#include <fmt/format.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg {

namespace {

/// A byte count as people read it: "4 GiB", "16 MiB", else "N bytes".
std::string byte_text(std::uintmax_t bytes) {
  constexpr std::uintmax_t kMiB = std::uintmax_t{1} << 20, kGiB = std::uintmax_t{1} << 30;
  if (bytes >= kGiB && bytes % kGiB == 0) return fmt::format("{} GiB", bytes / kGiB);
  if (bytes >= kMiB && bytes % kMiB == 0) return fmt::format("{} MiB", bytes / kMiB);
  return fmt::format("{} bytes", bytes);
}

/// Why stat(2) failed, as the problem of the path.
std::string unresolved(int error) {
  switch (error) {
    case ENOENT: return "no such file";
    case ELOOP: return "too many levels of symbolic links (a loop of symbolic links)";
    case ENOTDIR: return "no such file (a component of the path is not a folder)";
    case ENAMETOOLONG: return "the path is too long";
    case EACCES: return "cannot be reached (permission denied on a folder of the path)";
    default: return fmt::format("cannot be examined ({})", std::strerror(error));
  }
}

/// The file type of a stat(2) mode.
std::filesystem::file_type type_of(mode_t mode) {
  using std::filesystem::file_type;
  if (S_ISREG(mode)) return file_type::regular;
  if (S_ISDIR(mode)) return file_type::directory;
  if (S_ISFIFO(mode)) return file_type::fifo;
  if (S_ISSOCK(mode)) return file_type::socket;
  if (S_ISCHR(mode)) return file_type::character;
  if (S_ISBLK(mode)) return file_type::block;
  return file_type::unknown;
}

}  // namespace

const char* file_kind(std::filesystem::file_type type) {
  switch (type) {
    case std::filesystem::file_type::regular: return "a regular file";
    case std::filesystem::file_type::directory: return "a folder";
    case std::filesystem::file_type::fifo: return "a FIFO (named pipe)";
    case std::filesystem::file_type::socket: return "a socket";
    case std::filesystem::file_type::character: return "a character device";
    case std::filesystem::file_type::block: return "a block device";
    case std::filesystem::file_type::symlink: return "a symbolic link";
    default: return "a special file";
  }
}

std::string InputFileIssue::message(const std::filesystem::path& file) const {
  return (file.empty() ? std::string("'' (an empty path)") : file.string()) + ": " + problem + "; expected " + expected;
}

std::optional<InputFileIssue> input_file_issue(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                               std::string_view description, std::uintmax_t* bytes) {
  const std::string expected(description);
  if (file.empty()) return InputFileIssue{"names no file", expected};
  struct stat status {};
  if (::stat(file.c_str(), &status) != 0) {
    const int error = errno;
    return InputFileIssue{unresolved(error), expected};
  }
  if (!S_ISREG(status.st_mode))
    return InputFileIssue{std::string("is ") + file_kind(type_of(status.st_mode)) + ", not a regular file", expected};
  if (::access(file.c_str(), R_OK) != 0) {
    const int error = errno;
    return InputFileIssue{fmt::format("cannot be read ({})", std::strerror(error)), expected + " readable by this user"};
  }
  const auto size = static_cast<std::uintmax_t>(status.st_size);
  if (size > max_bytes)
    return InputFileIssue{fmt::format("is {} bytes, more than the limit of {} ({})", size, max_bytes, byte_text(max_bytes)),
                          fmt::format("{} of at most {}", expected, byte_text(max_bytes))};
  if (bytes != nullptr) *bytes = size;
  return std::nullopt;
}

std::uintmax_t check_input_file(const std::filesystem::path& file, std::uintmax_t max_bytes,
                                std::string_view description) {
  std::uintmax_t bytes = 0;
  if (const auto issue = input_file_issue(file, max_bytes, description, &bytes))
    throw DataError(file, "", issue->problem, issue->expected);
  return bytes;
}

}  // namespace gpilqg
