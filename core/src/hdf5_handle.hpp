#pragma once
/// @file hdf5_handle.hpp
/// The owner of one identifier of HDF5's C API (file, group, dataset, property list, ...), for the
/// readers that check a file through the C API before the C++ API reads it (dataset_size.cpp,
/// hdf5_self_contained.cpp). Private to core.

#include <hdf5.h>

namespace gpilqg {

/// Releases an HDF5 identifier of any kind (H5Idec_ref) when it goes out of scope; a negative
/// identifier (a failed H5*open) is held as invalid and released by nobody.
class Hdf5Handle {
 public:
  explicit Hdf5Handle(hid_t id) : id_(id) {}
  ~Hdf5Handle() {
    if (id_ >= 0) H5Idec_ref(id_);
  }
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
};

}  // namespace gpilqg
