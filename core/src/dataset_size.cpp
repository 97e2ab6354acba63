/// Declared HDF5 dataset sizes against the file's size and a fixed limit (dataset_size.hpp).

#include "gpilqg/core/dataset_size.hpp"

#include <fmt/format.h>

#include <hdf5.h>

#include <limits>
#include <stdexcept>
#include <type_traits>

#include "hdf5_handle.hpp"

namespace gpilqg {

static_assert(std::is_same_v<hid_t, std::int64_t>, "dataset_size.hpp passes HDF5 identifiers as std::int64_t");

namespace {

[[noreturn]] void cannot_tell(const char* what) {
  throw std::runtime_error(fmt::format("the HDF5 library cannot tell the {} of the object", what));
}

}  // namespace

std::optional<std::uint64_t> declared_values(const DeclaredSize& size) {
  std::uint64_t values = 1;
  for (const std::uint64_t d : size.dims)
    if (d == 0) return 0;
  for (const std::uint64_t d : size.dims) {
    if (values > std::numeric_limits<std::uint64_t>::max() / d) return std::nullopt;
    values *= d;
  }
  return values;
}

std::optional<std::string> declared_size_problem(const DeclaredSize& size, std::uintmax_t file_bytes) {
  const std::optional<std::uint64_t> values = declared_values(size);
  const std::string count =
      values ? std::to_string(*values) : fmt::format("more than {}", std::numeric_limits<std::uint64_t>::max());
  const double per_value = static_cast<double>(size.element_bytes == 0 ? 1 : size.element_bytes);
  const double capacity =
      static_cast<double>(file_bytes) / per_value * (size.filtered ? kMaxCompressionRatio : 1.0);
  if (!values || static_cast<double>(*values) > capacity)
    return fmt::format("declares {} values, more than a file of {} bytes can hold", count, file_bytes);
  if (*values > kMaxDatasetValues)
    return fmt::format("declares {} values, more than the limit of {} values per dataset", count, kMaxDatasetValues);
  return std::nullopt;
}

DeclaredSize hdf5_declared_size(std::int64_t object_id) {
  const H5I_type_t kind = H5Iget_type(object_id);
  if (kind != H5I_DATASET && kind != H5I_ATTR) cannot_tell("kind");
  const bool dataset = kind == H5I_DATASET;
  const Hdf5Handle space(dataset ? H5Dget_space(object_id) : H5Aget_space(object_id));
  const Hdf5Handle type(dataset ? H5Dget_type(object_id) : H5Aget_type(object_id));
  if (!space.valid()) cannot_tell("shape");
  if (!type.valid()) cannot_tell("type");
  DeclaredSize size;
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0) cannot_tell("rank");
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0) cannot_tell("shape");
  size.dims.assign(dims.begin(), dims.end());
  if (H5Sget_simple_extent_type(space.get()) == H5S_NULL) size.dims = {0};
  size.element_bytes = H5Tget_size(type.get());
  if (dataset) {
    const Hdf5Handle plist(H5Dget_create_plist(object_id));
    if (!plist.valid()) cannot_tell("storage");
    const int filters = H5Pget_nfilters(plist.get());
    if (filters < 0) cannot_tell("filters");
    size.filtered = filters > 0;
  }
  return size;
}

std::optional<std::string> hdf5_size_problem(std::int64_t object_id, std::uintmax_t file_bytes) {
  return declared_size_problem(hdf5_declared_size(object_id), file_bytes);
}

}  // namespace gpilqg
