#pragma once
/// @file config_model.hpp
/// The model a config names for its system: `[system] model = "F.toml"` (the simulator of `solve`,
/// `plan`, `rollout --cost` and `run`) or `[world] model = "W.toml"` (the world of `run`), a model
/// file of `gpilqg diagnose` (diagnosis/model_file.hpp: a preset, recalibrated parameters, effects
/// of the library and effects the user declared). Without the field, the system's bare preset.
///
/// As the simulator of GP-ILQG this model is the residual GP's mean function (the paper's
/// x_{t+1} = f_sim(x_t, u_t) + GP residual): what the diagnosis named, the model already has, and the
/// GP learns only what it still misses.

#include <optional>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/output_path.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {

class TomlFields;

/// The model file named by field `path` of the config `fields` (relative to the config's folder), for
/// `system`; or, when the field is absent, `system` at `preset`. The file's own errors (a model of
/// another system, an unknown effect or parameter, a value out of range) name its file, line and
/// field, behind the config's field. A model with an input delay fails too: the step models the
/// solvers and `run`'s rollouts use apply each control at once (only `gpilqg simulate` delays it).
ModelSpec read_config_model(const TomlFields& fields, const std::string& path, const std::string& system, Preset preset);

/// True when `name` names a model file of the diagnosis (it ends in ".toml", any case) rather than a
/// system or a MuJoCo model file.
bool is_diagnosis_model_file(const std::string& name);

/// The files a config names, resolved against its folder (TomlFields::file_path): each field of
/// `fields` that is given and names a file (a MuJoCo model or URDF, or a model file of the diagnosis),
/// as {"the config's <field>", path}, and after a MuJoCo model the files it includes and its assets
/// (mujoco_model_dependencies), as {"the config's <field>'s mesh file", path}. What a command that
/// reads the config must not overwrite, and what a run depends on.
std::vector<NamedInput> config_files(const TomlFields& fields, const std::vector<std::string>& paths);

/// The line that starts each file's text in config_files_text: "# <name> = <path>".
std::string config_file_header(const NamedInput& file);

/// "<name> = <path>" when `line` is a header of config_files_text, nothing otherwise.
std::optional<std::string> config_file_of_header(const std::string& line);

/// The text of each of `files` (an asset, a file not ending in .xml, .urdf or .toml: its size and
/// FNV-1a hash), each after its header (config_file_header): what a run read from them,
/// part of its identity (a resumed run and the parts of a merge must have read the same texts).
/// Throws InputError naming a file that cannot be read.
std::string config_files_text(const std::vector<NamedInput>& files);

}  // namespace gpilqg
