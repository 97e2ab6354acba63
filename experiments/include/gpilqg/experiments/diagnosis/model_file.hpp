#pragma once
/// @file model_file.hpp
/// The model a diagnosis starts from, as a TOML file (`gpilqg diagnose --model F.toml`, written back by
/// `--write-model`), and the `--add EFFECT[=VALUE]` option.
///
/// ```toml
/// [model]
/// system = "cartpole"        # must match --system
/// preset = "sim"             # "sim" or "real" (optional, default "sim")
///
/// [parameters]               # optional: recalibrated physical parameters (param:<name>)
/// pole_length = 1.3
///
/// [effects]                  # optional: library effects and their values
/// cart_coulomb_friction = 0.98          # one-parameter effects: a number
/// actuator_gain = { k = 1.1 }           # or a table of the parameters by name
/// ```
/// Every error is an InputError naming the file, the line and the field, and listing the valid choices.

#include <filesystem>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg::diagnosis {

/// Reads a model file. `system` is the --system given on the command line: the file must agree.
ModelSpec read_model_file(const std::filesystem::path& file, const std::string& system);

/// The TOML text of a model (the format above), preceded by `comment` lines written as "# ...".
std::string model_file_text(const ModelSpec& model, const std::vector<std::string>& comment = {});

/// Writes model_file_text to `file` atomically.
void write_model_file(const std::filesystem::path& file, const ModelSpec& model, const std::vector<std::string>& comment = {});

/// Parses "EFFECT" or "EFFECT=VALUE" for `system`. Throws InputError naming `option` (e.g. "--add"),
/// the text and the valid effect names, or saying why VALUE is not acceptable.
EffectRequest parse_add_option(const std::string& text, const std::string& system, const std::string& option = "--add");

}  // namespace gpilqg::diagnosis
