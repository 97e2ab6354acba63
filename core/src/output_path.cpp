/// Output paths checked before any work: kind of the existing entry, name length, writable folder.

#include "gpilqg/core/output_path.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/input_file.hpp"

namespace gpilqg {

namespace {

namespace fs = std::filesystem;

/// The folder that will hold `path`'s entry, or the nearest ancestor of it that exists; checked
/// for being a folder this process may create files in (access(2) with W_OK | X_OK).
std::optional<std::string> folder_problem(fs::path folder) {
  std::error_code error;
  folder = fs::absolute(folder.empty() ? fs::path(".") : folder, error);
  if (error) return "cannot resolve the folder (" + error.message() + ")";
  while (!fs::exists(fs::status(folder, error)) && folder.has_parent_path() && folder.parent_path() != folder)
    folder = folder.parent_path();
  const fs::file_status status = fs::status(folder, error);
  if (error) return "cannot inspect the folder " + folder.string() + " (" + error.message() + ")";
  if (status.type() != fs::file_type::directory)
    return folder.string() + " is " + file_kind(status.type()) + "; expected a folder";
  if (::access(folder.c_str(), W_OK | X_OK) != 0)
    return "the folder " + folder.string() + " is not writable (" + std::strerror(errno) + ")";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> output_extension_problem(const fs::path& file, const OutputFormat& format) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (std::find(format.extensions.begin(), format.extensions.end(), extension) != format.extensions.end())
    return std::nullopt;
  std::string names;
  for (std::size_t i = 0; i < format.extensions.size(); ++i)
    names += (i == 0 ? "" : i + 1 == format.extensions.size() ? " or " : ", ") + format.extensions[i];
  return format.what + "; expected a name ending in " + names;
}

std::optional<std::string> output_file_problem(const fs::path& file) {
  if (file.empty() || !file.has_filename()) return std::string("expected a file name, not a folder path");
  if (file.filename().string().size() > kMaxFileNameBytes)
    return "the file name has " + std::to_string(file.filename().string().size()) + " bytes; expected at most " +
           std::to_string(kMaxFileNameBytes);
  std::error_code error;
  const fs::file_status own = fs::symlink_status(file, error);
  if (error && error != std::errc::no_such_file_or_directory && error != std::errc::not_a_directory)
    return "cannot inspect it (" + error.message() + ")";
  if (fs::exists(own) && own.type() != fs::file_type::regular && own.type() != fs::file_type::symlink)
    return std::string("is ") + file_kind(own.type()) + "; expected a regular file or a new file name";
  return folder_problem(file.parent_path());
}

bool same_file(const fs::path& output, const fs::path& input) {
  struct stat a {}, b {};
  if (output.empty() || input.empty()) return false;
  if (::stat(output.c_str(), &a) != 0 || ::stat(input.c_str(), &b) != 0) return false;
  return a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

std::optional<std::string> input_overwrite_problem(const fs::path& output, const std::vector<NamedInput>& inputs) {
  for (const NamedInput& input : inputs)
    if (same_file(output, input.file))
      return "is the same file as " + input.name + " " + input.file.string() +
             ", an input of the command; expected a file that is not one of its inputs";
  return std::nullopt;
}

std::optional<std::string> output_problem(const fs::path& file, const OutputFormat& format,
                                          const std::vector<NamedInput>& inputs) {
  if (auto problem = output_file_problem(file)) return problem;
  if (auto problem = input_overwrite_problem(file, inputs)) return problem;
  return output_extension_problem(file, format);
}

std::optional<std::string> output_folder_problem(const fs::path& folder) {
  std::error_code error;
  const fs::file_status status = fs::status(folder, error);
  if (fs::exists(status) && status.type() != fs::file_type::directory)
    return std::string("is ") + file_kind(status.type()) + "; expected a folder";
  return folder_problem(folder);
}

}  // namespace gpilqg
