/// HDF5 files built in memory (the core driver) and written to the disk in one checked write.

#include "gpilqg/core/hdf5_memory_file.hpp"

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/atomic_file.hpp"
#include "gpilqg/core/hdf5_self_contained.hpp"

namespace gpilqg {

namespace {

/// A file-access property list for HDF5's core driver: the file lives in memory, grows in steps of
/// 1 MiB, and is never written back (backing_store = false).
H5::FileAccPropList in_memory_access() {
  H5::FileAccPropList access;
  if (H5Pset_fapl_core(access.getId(), std::size_t{1} << 20, false) < 0)
    throw std::runtime_error("HDF5: cannot select the in-memory (core) file driver");
  return access;
}

}  // namespace

H5::H5File create_hdf5_in_memory(const std::filesystem::path& name) {
  H5::Exception::dontPrint();
  return H5::H5File(name.string(), H5F_ACC_TRUNC, H5::FileCreatPropList::DEFAULT, in_memory_access());
}

H5::H5File open_hdf5_in_memory(const std::filesystem::path& file) {
  H5::Exception::dontPrint();
  H5::H5File opened(file.string(), H5F_ACC_RDWR, H5::FileCreatPropList::DEFAULT, in_memory_access());
  check_hdf5_self_contained(file, opened.getId());
  return opened;
}

void save_hdf5_image(H5::H5File& file, const std::filesystem::path& destination) {
  const hid_t id = file.getId();
  if (H5Fflush(id, H5F_SCOPE_GLOBAL) < 0)
    throw std::runtime_error(destination.string() + ": HDF5 could not flush the in-memory file");
  const ssize_t size = H5Fget_file_image(id, nullptr, 0);
  if (size < 0) throw std::runtime_error(destination.string() + ": HDF5 could not size the file image");
  std::vector<char> image(static_cast<std::size_t>(size));
  if (size > 0 && H5Fget_file_image(id, image.data(), image.size()) != size)
    throw std::runtime_error(destination.string() + ": HDF5 could not copy the file image");
  file.close();
  write_new_file(destination, std::string_view(image.data(), image.size()));
}

void write_hdf5_atomically(const std::filesystem::path& target, const std::function<void(H5::H5File&)>& fill) {
  write_atomically(target, [&](const std::filesystem::path& temporary) {
    H5::H5File file = create_hdf5_in_memory(temporary);
    fill(file);
    save_hdf5_image(file, temporary);
  });
}

void update_hdf5_atomically(const std::filesystem::path& target, const std::function<void(H5::H5File&)>& fill) {
  write_atomically(target, [&](const std::filesystem::path& temporary) {
    std::error_code error;
    H5::H5File file = std::filesystem::exists(target, error) ? open_hdf5_in_memory(target)
                                                              : create_hdf5_in_memory(temporary);
    fill(file);
    save_hdf5_image(file, temporary);
  });
}

}  // namespace gpilqg
