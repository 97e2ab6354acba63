/// Raw HDF5 logs: every numeric dataset that is a vector (N, N x 1 or 1 x N) is a column named by its
/// path without the leading '/'. Datasets of other shapes or types are kept as unusable columns; a
/// dataset declaring more values than the file can hold is an error (Hdf5Reader, dataset_size.hpp).

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"

namespace gpilqg {

RawLog read_raw_log_hdf5(const std::filesystem::path& file) {
  RawLog log;
  log.file = file;
  log.format = LogFormat::Hdf5;
  std::unique_ptr<Hdf5Reader> reader;
  try {
    reader = std::make_unique<Hdf5Reader>(file);
  } catch (const DataError&) {
    throw;  // not a readable regular file of at most kMaxDataFileBytes: already names the file
  } catch (const std::runtime_error& e) {
    throw DataError(file, "", fmt::format("cannot open it as HDF5 ({})", e.what()), "an HDF5 file of 1-D datasets");
  }
  for (const std::string& path : reader->datasets("/")) {
    LogColumn column{path.substr(1), {}, ""};
    std::vector<std::uint64_t> shape;
    try {
      shape = reader->shape(path);
    } catch (const std::runtime_error& e) {
      column.unusable = e.what();
    }
    const bool vector = shape.size() == 1 || (shape.size() == 2 && (shape[0] == 1 || shape[1] == 1));
    if (column.unusable.empty() && !vector) {
      std::string dims;
      for (const auto d : shape) dims += (dims.empty() ? "" : " x ") + std::to_string(d);
      column.unusable = shape.empty() ? "a scalar, not a vector" : fmt::format("a {} array, not a vector", dims);
    }
    if (column.unusable.empty()) {
      try {
        column.values = reader->read_array(path);
      } catch (const DataError&) {
        throw;  // declares more values than the file can hold: the file is damaged
      } catch (const std::runtime_error& e) {
        column.unusable = fmt::format("not numeric ({})", e.what());
      }
    }
    for (std::size_t i = 0; i < column.values.size() && column.unusable.empty(); ++i)
      if (!std::isfinite(column.values[i])) column.unusable = fmt::format("element {} is not finite", i);
    log.columns.push_back(std::move(column));
  }
  return log;
}

}  // namespace gpilqg
