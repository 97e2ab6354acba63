/// Choosing a raw-log reader by extension, and naming places in a log for error messages.

#include "gpilqg/core/raw_log.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/utf8.hpp"
#include "name_list.hpp"

namespace gpilqg {

namespace {

std::string without_leading_slash(const std::string& name) {
  return !name.empty() && name.front() == '/' ? name.substr(1) : name;
}

}  // namespace

const LogColumn* RawLog::find(const std::string& name) const {
  const std::string key = format == LogFormat::Hdf5 ? without_leading_slash(name) : name;
  for (const LogColumn& column : columns)
    if (column.name == key) return &column;
  return nullptr;
}

std::string RawLog::column_names() const {
  std::vector<std::string_view> names;
  names.reserve(columns.size());
  for (const LogColumn& column : columns) names.push_back(column.name);
  return name_list::quoted_list(names);
}

std::string RawLog::location(const std::string& name) const {
  switch (format) {
    case LogFormat::Csv: return fmt::format("column '{}'", name);
    case LogFormat::Mat: return fmt::format("variable '{}'", name);
    case LogFormat::Hdf5: return fmt::format("dataset '/{}'", without_leading_slash(name));
  }
  return name;
}

std::string RawLog::location(const std::string& name, long row) const {
  if (format == LogFormat::Csv) return fmt::format("line {}, column '{}'", row + 2, name);
  return fmt::format("{}, element {}", location(name), row);
}

RawLog read_raw_log(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  check_input_file(file, kMaxDataFileBytes, "a log file");
  RawLog log;
  if (extension == ".csv") log = read_raw_log_csv(file);
  else if (extension == ".mat") log = read_raw_log_mat(file);
  else if (extension == ".h5" || extension == ".hdf5") log = read_raw_log_hdf5(file);
  else
    throw DataError(file, "", fmt::format("unknown extension '{}'", extension), "a log ending in .csv, .mat, .h5 or .hdf5");
  // Column names reach the import report (and its JSON): names that are not UTF-8 are refused
  // here, for every format, with their bytes shown escaped.
  for (const LogColumn& column : log.columns)
    if (!is_valid_utf8(column.name))
      throw DataError(file, log.location(escaped_bytes(column.name)), "the column's name is not valid UTF-8",
                      "column names in UTF-8");
  const bool any_usable =
      std::any_of(log.columns.begin(), log.columns.end(), [](const LogColumn& c) { return c.unusable.empty(); });
  if (!any_usable)
    throw DataError(file, "", "no numeric column", "named numeric vectors, one per column (docs/data-import.md)");
  return log;
}

}  // namespace gpilqg
