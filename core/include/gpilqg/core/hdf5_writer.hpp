#pragma once
/// @file hdf5_writer.hpp
/// One small API for writing numeric results to HDF5, shared by every result and report file of the
/// project (run results, diagnosis and profile reports): datasets and attributes are addressed by
/// '/'-separated paths whose groups are created on demand. Values are IEEE double (little endian) in
/// row-major order, so h5py reads an n x T Matrix as an array of shape (n, T). The HDF5 C++ API stays
/// inside core (the header exposes none of it).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

class Hdf5Writer {
 public:
  /// Starts the file `file` (replacing any file there when it is written). It is built in memory and
  /// written to the disk by close() in one checked write (hdf5_memory_file.hpp); callers write to a
  /// write_atomically temporary.
  explicit Hdf5Writer(const std::filesystem::path& file);
  /// Writes the file when close() was not called, ignoring errors; dropped during stack unwinding.
  ~Hdf5Writer();
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  /// A 2-D dataset rows x cols.
  void write_matrix(const std::string& path, const MatrixCRef& values);
  /// A 1-D dataset.
  void write_vector(const std::string& path, const VectorCRef& values);
  void write_vector(const std::string& path, const std::vector<double>& values);
  void write_vector(const std::string& path, const std::vector<int>& values);
  /// A scalar dataset.
  void write_scalar(const std::string& path, double value);
  /// An N-D dataset of shape `dims` from `values` in row-major (C) order; sizes must agree.
  void write_array(const std::string& path, const std::vector<std::uint64_t>& dims, const std::vector<double>& values);

  /// Attributes on a group or dataset (the group "/" is the file's root); groups are created on demand.
  void attribute(const std::string& object, const std::string& name, const std::string& value);
  void attribute(const std::string& object, const std::string& name, double value);
  void attribute(const std::string& object, const std::string& name, std::int64_t value);
  void attribute(const std::string& object, const std::string& name, const std::vector<std::string>& values);
  /// A 1-D float64 attribute (h5py reads it as a NumPy array).
  void attribute(const std::string& object, const std::string& name, const std::vector<double>& values);

  /// A soft link at `path` to the object `target` (h5py follows it transparently).
  void link(const std::string& path, const std::string& target);

  /// Writes the file to the disk and closes it; throws FileWriteError when the disk refuses (full,
  /// file-size limit, I/O error). Later calls throw.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::filesystem::path file_;
};

}  // namespace gpilqg
