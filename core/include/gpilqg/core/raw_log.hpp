#pragma once
/// @file raw_log.hpp
/// A robot's log read as named numeric columns, before any mapping (docs/data-import.md):
/// - CSV (.csv): a header of column names, then one row per sample; fields are comma-separated and
///   trimmed of spaces; any column names.
/// - MAT (.mat, MATLAB v4 / v5 / v7.3 through matio): every real numeric variable that is a vector
///   (1 x N or N x 1) is a column named by the variable; a struct's vector fields are columns named
///   "struct.field".
/// - HDF5 (.h5 / .hdf5): every numeric dataset that is a vector (N, N x 1 or 1 x N) is a column named
///   by its path without the leading '/', e.g. "time" or "sensors/cart_pos".
/// Everything else (text columns, matrices, cells, strings) is kept by name as a column that cannot
/// be used, with the reason, so an import can list it among the ignored columns and a map that
/// names it fails with that reason.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

enum class LogFormat { Csv, Mat, Hdf5 };

struct LogColumn {
  std::string name;
  std::vector<double> values;
  /// Why the column cannot be used (e.g. "line 7: 'n/a' is not a number", "a 3 x 200 matrix"),
  /// empty when it can. Values that do not parse are only an error when a map uses the column.
  std::string unusable;
};

struct RawLog {
  std::filesystem::path file;
  LogFormat format = LogFormat::Csv;
  std::vector<LogColumn> columns;

  /// The column called `name` (for HDF5 a leading '/' is ignored), or nullptr.
  const LogColumn* find(const std::string& name) const;
  /// The names of the columns, quoted and comma-separated, for "expected one of ..." messages: at
  /// most the first 10, then "... and N more", so that a log of any width gives a short message.
  std::string column_names() const;
  /// Where sample `row` (0-based) of column `name` is in the file, for an error message:
  /// "line 12, column 'timestamp'" (CSV, header = line 1), "variable 'timestamp', element 11" (MAT),
  /// "dataset '/timestamp', element 11" (HDF5).
  std::string location(const std::string& name, long row) const;
  /// Where the whole column is: "column 'x'", "variable 'x'", "dataset '/x'".
  std::string location(const std::string& name) const;
};

/// Reads `file` by its extension (case-insensitive): .csv, .mat, .h5 / .hdf5. Throws DataError
/// (measurements.hpp) naming the file, and the line or variable or dataset, for: a path that is not a
/// readable regular file of at most kMaxDataFileBytes (check_input_file, input_file.hpp: missing, a
/// directory, a FIFO, a device, a loop of symbolic links, too large), another extension, an empty CSV,
/// a CSV row whose field count differs from the header's, a duplicate column name, an HDF5 dataset
/// declaring more values than the file can hold (dataset_size.hpp), and a log without any usable
/// column. The per-format readers below make the same file check.
RawLog read_raw_log(const std::filesystem::path& file);

RawLog read_raw_log_csv(const std::filesystem::path& file);
RawLog read_raw_log_mat(const std::filesystem::path& file);
RawLog read_raw_log_hdf5(const std::filesystem::path& file);

}  // namespace gpilqg
