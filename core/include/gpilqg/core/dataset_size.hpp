#pragma once
/// @file dataset_size.hpp
/// The check every HDF5 reader makes before it allocates memory for a dataset or attribute: a damaged
/// or hostile file can declare any shape (a 4 KB file can declare 2^31 x 3 values), so the declared
/// number of values is compared with
///  (a) what the file's bytes can hold: file bytes / bytes per stored value, times kMaxCompressionRatio
///      when the dataset is compressed (filtered); and
///  (b) kMaxDatasetValues, whatever the file's size,
/// and a reader refuses the dataset, naming it, instead of failing in the allocation (std::bad_alloc)
/// or taking all the memory. Data stored outside the file (external storage, virtual datasets) is
/// refused before, when the file is opened (hdf5_self_contained.hpp).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace gpilqg {

/// The most values any reader accepts in one dataset or attribute: 2^28 = 268435456 (2 GiB as float64).
inline constexpr std::uint64_t kMaxDatasetValues = std::uint64_t{1} << 28;

/// How many values per stored byte a compressed dataset may declare beyond its uncompressed size:
/// deflate expands at most about 1032:1.
inline constexpr double kMaxCompressionRatio = 1100.0;

/// What a reader knows about a dataset before reading it.
struct DeclaredSize {
  std::vector<std::uint64_t> dims;  ///< the declared shape (empty for a scalar: one value)
  std::uint64_t element_bytes = 8;  ///< bytes of one stored value
  bool filtered = false;            ///< compressed (any filter in the dataset's pipeline)
};

/// The declared number of values, or nullopt when the product of the dims does not fit 64 bits.
std::optional<std::uint64_t> declared_values(const DeclaredSize& size);

/// Nullopt when the dataset can be read, else the problem, to follow "<file>:<dataset>: ":
///   "declares 402653184 values, more than a file of 4096 bytes can hold"
///   "declares 402653184 values, more than the limit of 268435456 values per dataset"
std::optional<std::string> declared_size_problem(const DeclaredSize& size, std::uintmax_t file_bytes);

/// The DeclaredSize of an open HDF5 dataset or attribute, given by its identifier (an hid_t, e.g.
/// H5::DataSet::getId()). Throws std::runtime_error when the library cannot tell.
DeclaredSize hdf5_declared_size(std::int64_t object_id);

/// declared_size_problem(hdf5_declared_size(object_id), file_bytes).
std::optional<std::string> hdf5_size_problem(std::int64_t object_id, std::uintmax_t file_bytes);

}  // namespace gpilqg
