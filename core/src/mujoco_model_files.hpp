#pragma once
/// @file mujoco_model_files.hpp
/// The check of every file a MuJoCo model names, made before MuJoCo opens any of them: MuJoCo opens
/// included files and asset files without asking what they are, so a FIFO named by
/// `<include file=...>` or `<mesh file=...>` would block the load forever and /dev/zero would be read
/// until the memory runs out. Each file is checked like the model itself (input_file.hpp), found the
/// way MuJoCo 2.2 finds it:
///  - `<include file="F">`: F relative to the folder of the main model file (also from an included
///    file), recursively through the included files;
///  - `<mesh file>`, `<skin file>`, `<hfield file>`: relative to `<compiler meshdir>`, itself relative
///    to the main model's folder unless absolute; an absolute file name is used as it is;
///  - `<texture file, fileright, fileleft, fileup, filedown, filefront, fileback>`: the same with
///    `<compiler texturedir>`;
///  - a URDF's `<mesh filename>`: its base name (MuJoCo strips the path of URDF mesh names unless
///    `<mujoco><compiler strippath="false">`) relative to the meshdir of the URDF's `<mujoco><compiler>`.
/// The last `<compiler>` attribute in document order (includes expanded) applies, as in MuJoCo.
/// A file that does not exist is left to MuJoCo, which reports it when it needs it (a URDF's
/// visual meshes, for one, are discarded unread); anything else that is not a readable regular file
/// of a sane size is refused. The XML is read with tinyxml2, the parser MuJoCo uses.

#include <string>

namespace gpilqg {

/// Checks the files named by the model at `path` whose text is `text` (MJCF or URDF). Throws
/// std::invalid_argument "<file>: <problem>; expected <a mesh file (<mesh file="F"> in M, line L)>"
/// for the first file that is not a readable regular file of at most kMaxDataFileBytes (assets) or
/// kMaxConfigFileBytes (included XML). Text that is not well-formed XML is left to MuJoCo's message.
void check_mujoco_model_files(const std::string& path, const std::string& text);

/// The bytes of a model file (the model itself or one it includes); throws std::invalid_argument
/// "<file>: cannot read the model file" when reading fails.
std::string model_file_text(const std::string& file);

}  // namespace gpilqg
