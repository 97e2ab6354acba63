#pragma once
/// @file csv_text.hpp
/// Splitting CSV text into lines and fields, shared by the readers of measurement files
/// (measurements_csv.cpp) and of raw robot logs (raw_log_csv.cpp). Views into the text; no quoting
/// (neither format has quoted fields).

#include <string_view>
#include <vector>

namespace gpilqg::csv_text {

/// The text split into lines without their "\n" or "\r\n"; a final newline does not start a line.
std::vector<std::string_view> split_lines(std::string_view text);

/// The comma-separated fields of one line, as they are (nothing trimmed).
std::vector<std::string_view> split_fields(std::string_view line);

}  // namespace gpilqg::csv_text
