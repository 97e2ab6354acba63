#pragma once
/// @file hdf5_common.hpp
/// What hdf5_writer.cpp and hdf5_reader.cpp share: HDF5 C++ exceptions turned into errors that name
/// the file and the object, and the string type of the project's string attributes (UTF-8, variable
/// length, as h5py writes them).

#include <filesystem>
#include <stdexcept>
#include <string>

#include <H5Cpp.h>

namespace gpilqg::hdf5_detail {

/// Runs `action`, turning an H5::Exception into std::runtime_error
/// "<file>: <what> '<object>' failed (HDF5: <detail>)".
template <class Action>
decltype(auto) guarded(const std::filesystem::path& file, const std::string& object, const char* what, Action&& action) {
  try {
    return action();
  } catch (const H5::Exception& e) {
    throw std::runtime_error(file.string() + ": " + what + " '" + object + "' failed (HDF5: " + e.getDetailMsg() + ")");
  }
}

inline H5::StrType utf8_string_type() {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

}  // namespace gpilqg::hdf5_detail
