#pragma once
/// @file hdf5_memory_file.hpp
/// The one way the project writes HDF5 files: HDF5 builds the file in memory, and its finished
/// image reaches the disk through write_new_file (atomic_file.hpp), whose every write, fsync and
/// close is checked.
///
/// Why not let HDF5 write to the disk itself: on a full disk (or at a file-size limit) its failures
/// surface late and partly. The C++ API's destructors swallow the errors of H5Dclose and H5Gclose,
/// a file whose objects could not be closed stays open, H5Fclose then "succeeds" without writing,
/// and the library crashes at exit while flushing it. A damaged file could thus be renamed over a
/// good one. In memory (HDF5's "core" driver without a backing store) nothing of this can happen,
/// and the disk sees exactly one checked write.

#include <filesystem>
#include <functional>

#include <H5Cpp.h>

namespace gpilqg {

/// A new, empty HDF5 file held in memory; `name` only identifies it (nothing is created on disk).
H5::H5File create_hdf5_in_memory(const std::filesystem::path& name);

/// An editable in-memory copy of the existing HDF5 file `file` (the file itself is not modified).
/// Throws DataError when the file refers to data outside it (check_hdf5_self_contained).
H5::H5File open_hdf5_in_memory(const std::filesystem::path& file);

/// Flushes the in-memory `file`, writes its image to the new file `destination` (write_new_file) and
/// closes `file`. Throws FileWriteError when the disk refuses, std::runtime_error naming
/// `destination` when HDF5 cannot produce the image.
void save_hdf5_image(H5::H5File& file, const std::filesystem::path& destination);

/// write_atomically for HDF5: `fill` writes into an in-memory file whose image replaces `target`.
void write_hdf5_atomically(const std::filesystem::path& target, const std::function<void(H5::H5File&)>& fill);

/// As write_hdf5_atomically, but `fill` edits an in-memory copy of `target` when it exists (an
/// empty file otherwise), so that groups can be added to a file without rewriting its callers.
void update_hdf5_atomically(const std::filesystem::path& target, const std::function<void(H5::H5File&)>& fill);

}  // namespace gpilqg
