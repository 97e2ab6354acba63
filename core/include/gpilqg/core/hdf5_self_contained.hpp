#pragma once
/// @file hdf5_self_contained.hpp
/// The check every HDF5 reader makes right after opening a file: everything in it must be stored in
/// the file itself. HDF5 can make an object of one file stand for data elsewhere, and the library
/// opens that elsewhere without asking, past the check of the path the user gave (input_file.hpp):
///  - an external link (h5py ExternalLink) names an object of another file, which may be a FIFO
///    (opening it blocks until a writer comes) or a device;
///  - external raw storage (h5py create_dataset(..., external=[...])) keeps a dataset's values in
///    other files, read as they are: /dev/zero reads as data, a FIFO blocks;
///  - a virtual dataset maps regions of datasets in other files;
///  - a user-defined link class can resolve to anything its plugin decides.
/// A file holding any of them is refused as a whole, naming the object, before any object of it is
/// opened: the program's files never hold them, and a reader that refuses them everywhere cannot
/// reach another file through a soft link either. Soft links stay allowed: they resolve inside the
/// file (the result files use them, Hdf5Writer::link).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace gpilqg {

/// An object of an HDF5 file that refers to data outside it.
struct Hdf5OutsideReference {
  std::string object;   ///< its path in the file, e.g. "/episodes/0/x"
  std::string problem;  ///< e.g. "is an external link to pipe.h5:/x"
};

/// The first object of the open file `file_id` (an hid_t) that refers to data outside the file, or
/// nullopt when there is none. Visits every link reachable from the root group through hard links
/// (H5Lvisit, which never follows soft or external links) and opens every dataset's creation property
/// list (its layout and external file list; no data is read and no other file is opened). Throws
/// std::runtime_error when the HDF5 library cannot list the file.
std::optional<Hdf5OutsideReference> hdf5_outside_reference(std::int64_t file_id);

/// hdf5_outside_reference for the readers: throws DataError (measurements.hpp)
/// "<file>:<object>: <problem>; expected data stored in the file itself".
void check_hdf5_self_contained(const std::filesystem::path& file, std::int64_t file_id);

}  // namespace gpilqg
