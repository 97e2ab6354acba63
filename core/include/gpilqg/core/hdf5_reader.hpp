#pragma once
/// @file hdf5_reader.hpp
/// The reading side of hdf5_writer.hpp: datasets and attributes addressed by '/'-separated paths,
/// values converted to double whatever their stored numeric type, 2-D datasets read in row-major order
/// into an Eigen matrix of the same shape (so what Hdf5Writer::write_matrix wrote comes back equal bit
/// for bit). Every failure throws std::runtime_error naming the file, the object and what was expected;
/// the HDF5 C++ API stays inside core. Bad input files throw DataError (measurements.hpp, a
/// std::runtime_error): a path that is not a readable regular file of at most kMaxDataFileBytes
/// (input_file.hpp), and a dataset or attribute declaring more values than the file can hold or than
/// kMaxDatasetValues (dataset_size.hpp), refused before anything is allocated for it, and a file with
/// an object stored in another file (an external link, external raw storage, a virtual dataset),
/// refused when it is opened (hdf5_self_contained.hpp).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

class Hdf5Reader {
 public:
  /// Opens `file` read-only. Throws DataError when it is not a readable regular file of at most
  /// kMaxDataFileBytes (check_input_file), std::runtime_error naming the file when it is not HDF5.
  explicit Hdf5Reader(const std::filesystem::path& file);
  ~Hdf5Reader();
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  const std::filesystem::path& file() const { return file_; }

  /// Whether a group or dataset exists at `path` (every parent must be a group).
  bool exists(const std::string& path) const;
  /// The full paths of every dataset below `group` ("/": the whole file), depth first, sorted by name.
  std::vector<std::string> datasets(const std::string& group = "/") const;
  /// The target path of the soft link at `path` (what Hdf5Writer::link stored, e.g. "/task/gp_ilqg_exact");
  /// std::nullopt when nothing is at `path` or it is a group or dataset itself.
  std::optional<std::string> soft_link_target(const std::string& path) const;
  /// The shape of the dataset at `path` (empty for a scalar).
  std::vector<std::uint64_t> shape(const std::string& path) const;

  /// A 2-D dataset (a 1-D one of length N reads as N x 1).
  Matrix read_matrix(const std::string& path) const;
  /// A 1-D dataset (or a scalar, as one entry).
  Vector read_vector(const std::string& path) const;
  /// A scalar dataset, or a dataset with exactly one value.
  double read_scalar(const std::string& path) const;
  /// Any dataset, flattened in row-major (C) order; its shape is shape(path).
  std::vector<double> read_array(const std::string& path) const;

  /// Attributes of a group or dataset ("/" is the root).
  std::string string_attribute(const std::string& object, const std::string& name) const;
  double number_attribute(const std::string& object, const std::string& name) const;
  /// A numeric attribute of any shape, flattened (a scalar gives one entry).
  std::vector<double> number_list_attribute(const std::string& object, const std::string& name) const;
  std::vector<std::string> string_list_attribute(const std::string& object, const std::string& name) const;
  bool has_attribute(const std::string& object, const std::string& name) const;
  /// The names of every attribute of a group or dataset, sorted.
  std::vector<std::string> attributes(const std::string& object) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::filesystem::path file_;
};

}  // namespace gpilqg
