/// Raw CSV logs: a header of any column names, then comma-separated numbers. Unlike measurement
/// files (measurements_csv.cpp), robot logs are taken as loggers write them: fields are trimmed of
/// spaces and tabs, "\r\n" line endings, a UTF-8 byte-order mark and blank lines at the end are
/// accepted. A field that is not a number makes its column unusable (named with the line), which is
/// only an error when the map uses that column.

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "csv_text.hpp"
#include "name_list.hpp"

namespace gpilqg {

namespace {

std::string read_text(const std::filesystem::path& file) {
  check_input_file(file, kMaxDataFileBytes, "a log file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw DataError(file, "", "cannot open the file for reading", "a readable log file");
  std::ostringstream contents;
  contents << in.rdbuf();
  return std::move(contents).str();
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

/// The fields of a line, trimmed of spaces and tabs.
std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields = csv_text::split_fields(line);
  for (std::string_view& field : fields) field = trim(field);
  return fields;
}

/// The lines of the text, without blank lines at its end.
std::vector<std::string_view> split_lines(std::string_view text) {
  std::vector<std::string_view> lines = csv_text::split_lines(text);
  while (!lines.empty() && trim(lines.back()).empty()) lines.pop_back();
  return lines;
}

/// The number in `field`, or nothing when it is not a finite number written plainly.
std::optional<double> parse_number(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (field.empty() || error != std::errc() || end != field.data() + field.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

RawLog read_raw_log_csv(const std::filesystem::path& file) {
  std::string text = read_text(file);
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  const std::vector<std::string_view> lines = split_lines(text);
  if (lines.empty()) throw DataError(file, "", "the file is empty", "a header of column names, then one row per sample");

  RawLog log;
  log.file = file;
  log.format = LogFormat::Csv;
  std::set<std::string> seen;
  for (const std::string_view name : split_fields(lines[0])) {
    if (name.empty())
      throw DataError(file, "line 1", fmt::format("column {} has no name", log.columns.size() + 1), "a name for every column");
    if (!seen.insert(std::string(name)).second)
      throw DataError(file, "line 1", fmt::format("column {} appears twice", name_list::quoted(name)), "distinct column names");
    log.columns.push_back({std::string(name), {}, ""});
  }
  const std::size_t width = log.columns.size();
  for (auto& column : log.columns) column.values.reserve(lines.size() - 1);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const long line = static_cast<long>(i) + 1;
    const std::vector<std::string_view> fields = split_fields(lines[i]);
    if (fields.size() != width)
      throw DataError(file, fmt::format("line {}", line), fmt::format("{} fields", fields.size()),
                      fmt::format("{} fields, one per header column", width));
    for (std::size_t c = 0; c < width; ++c) {
      LogColumn& column = log.columns[c];
      const std::optional<double> value = parse_number(fields[c]);
      if (!value && column.unusable.empty())
        column.unusable = fmt::format("line {}: '{}' is not a finite number", line, fields[c].substr(0, 40));
      column.values.push_back(value.value_or(0.0));
    }
  }
  if (lines.size() < 2) throw DataError(file, "line 1", "a header without data rows", "one row per sample after the header");
  return log;
}

}  // namespace gpilqg
