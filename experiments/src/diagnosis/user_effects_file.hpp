#pragma once
/// @file user_effects_file.hpp
/// The [[user_effects]] entries of a model file (model_file.hpp): forces a user declares without
/// writing C++ (basis_force.hpp), read into library entries and written back.

#include <filesystem>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "gpilqg/core/effect_library.hpp"

namespace gpilqg::diagnosis {

/// The user effects declared in `root` (a model file's table) for `system`, in file order. Every error
/// is an InputError "<file>:line N: field 'user_effects[i].terms[j]': <problem>" listing the valid
/// choices (the basis, the coordinates, the controls), for unknown keys, wrong types, an invalid
/// declaration (basis_force.hpp), a name of the library or declared twice.
std::vector<LibraryEffect> read_user_effects(const toml::table& root, const std::filesystem::path& file,
                                             const std::string& system);

/// The [[user_effects]] TOML text of `model.user_effects` (empty when there are none). Throws
/// std::invalid_argument for a user effect that is not a declared basis force (one a C++ caller made).
std::string user_effects_text(const ModelSpec& model);

}  // namespace gpilqg::diagnosis
