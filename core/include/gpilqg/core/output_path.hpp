#pragma once
/// @file output_path.hpp
/// Checks of a path that a command will write, made before any computation, so that a wrong
/// `--out` costs nothing: a result file is replaced by an atomic rename (atomic_file.hpp), which
/// needs a writable folder and must never replace a device, a FIFO or a folder.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace gpilqg {

/// What a command writes to an output path and the names it accepts for it: `what` is the
/// sentence's subject and verb ("plan writes an HDF5 policy file"), `extensions` the accepted
/// endings, lower case with their dot ({".h5", ".hdf5"}). A file of a fixed format must carry its
/// format's extension, so that every reader (gpilqg's own, h5py, pandas) that picks a format by the
/// name reads it back as what it is.
struct OutputFormat {
  std::string what;
  std::vector<std::string> extensions;
};

/// The extensions of each fixed format gpilqg writes.
inline const std::vector<std::string> kHdf5Extensions{".h5", ".hdf5"};
inline const std::vector<std::string> kCsvExtensions{".csv"};
inline const std::vector<std::string> kTomlExtensions{".toml"};
inline const std::vector<std::string> kJsonExtensions{".json"};
/// A measurement file or log: CSV or HDF5, chosen by the name.
inline const std::vector<std::string> kMeasurementExtensions{".csv", ".h5", ".hdf5"};

/// Why `file`'s name does not end in one of `format.extensions` (compared case-insensitively), or
/// nullopt: "plan writes an HDF5 policy file; expected a name ending in .h5 or .hdf5".
std::optional<std::string> output_extension_problem(const std::filesystem::path& file, const OutputFormat& format);

/// Why `file` cannot receive a result file, or nullopt when it can. It must be absent, a regular
/// file or a symbolic link (the link is replaced, never written through); its name must fit the
/// file system's limit (255 bytes); its folder, or the nearest existing ancestor when the folder
/// will be created, must be a folder this process can write into.
std::optional<std::string> output_file_problem(const std::filesystem::path& file);

/// Whether writing `output` would replace the existing file `input`: both name one file, by device
/// and inode, with symbolic links followed on both sides (a hard link, or a symbolic link to the
/// input, counts as the input). An output that is a symbolic link to an input is refused by the
/// commands although the atomic rename would replace the link, not the file: the user meant that
/// file. False when either does not exist or cannot be inspected.
bool same_file(const std::filesystem::path& output, const std::filesystem::path& input);

/// A file a command or call reads, as messages name it: the option, argument or config field that
/// gave it ("--data", "CONFIG", "the config's [system] model") and its path; an empty path (not
/// given) is skipped.
struct NamedInput {
  std::string name;
  std::filesystem::path file;
};

/// Why writing `output` would replace one of `inputs` (same_file), or nullopt: "is the same file as
/// <name> <path>, an input of the command; expected a file that is not one of its inputs".
std::optional<std::string> input_overwrite_problem(const std::filesystem::path& output,
                                                   const std::vector<NamedInput>& inputs);

/// Every check of a result file before any work, in this order: output_file_problem, then
/// input_overwrite_problem against `inputs` (the input named is the more telling culprit), then
/// output_extension_problem against `format`; nullopt when it passes all three.
std::optional<std::string> output_problem(const std::filesystem::path& file, const OutputFormat& format,
                                          const std::vector<NamedInput>& inputs);

/// Why `folder` cannot receive output files (e.g. figures), or nullopt when it can: it must be a
/// folder or absent, and it or its nearest existing ancestor must be writable.
std::optional<std::string> output_folder_problem(const std::filesystem::path& folder);

}  // namespace gpilqg
