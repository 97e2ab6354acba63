#include "gpilqg/experiments/config_model.hpp"

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string_view>

#include <fmt/format.h>

#include "gpilqg/core/fnv_hash.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/mujoco_system.hpp"
#include "gpilqg/core/system_registry.hpp"

#include "gpilqg/core/output_path.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/diagnosis/model_file.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {

bool is_diagnosis_model_file(const std::string& name) {
  return !output_extension_problem(name, OutputFormat{"a model file", kTomlExtensions}).has_value();
}

ModelSpec read_config_model(const TomlFields& f, const std::string& path, const std::string& system, Preset preset) {
  ModelSpec model;
  model.system = system;
  model.preset = preset;
  if (!f.has(path)) return model;
  const std::filesystem::path file = f.file_path(path);
  if (!is_diagnosis_model_file(file.string()))
    f.fail(path, fmt::format("'{}' is not a model file of `gpilqg diagnose`; expected a .toml file (docs/formats.md, "
                             "\"Model files\")",
                             file.string()));
  try {
    model = diagnosis::read_model_file(file, system, "the config's [system] name");
  } catch (const InputError& e) {
    f.fail(path, e.what());
  }
  if (model.input_delay != 0.0)
    f.fail(path, fmt::format("{} has an input delay of {} control periods; expected none: the solvers and `run`'s "
                             "rollouts apply each control at once (`gpilqg simulate` applies a delay)",
                             file.string(), model.input_delay));
  return model;
}

namespace {

/// How every name of config_files starts, and so every header of config_files_text after "# ".
constexpr std::string_view kConfigFileName = "the config's ";

}  // namespace

std::vector<NamedInput> config_files(const TomlFields& f, const std::vector<std::string>& paths) {
  std::vector<NamedInput> out;
  for (const std::string& path : paths) {
    if (!f.has(path)) continue;
    const std::string named = f.string(path);
    if (!is_model_file_name(named) && !is_diagnosis_model_file(named)) continue;
    const std::string name = std::string(kConfigFileName) + path;
    out.push_back({name, f.file_path(path)});
    if (!is_model_file_name(named)) continue;
    // A MuJoCo model's included files and assets are the model too.
    try {
      for (const ModelDependency& d : mujoco_model_dependencies(f.file_path(path).string()))
        out.push_back({fmt::format("{}'s {}", name, d.what.substr(d.what.find(' ') + 1)), d.file});
    } catch (const std::invalid_argument& e) {
      f.fail(path, e.what());
    }
  }
  return out;
}

std::string config_file_header(const NamedInput& file) { return fmt::format("# {} = {}", file.name, file.file.string()); }

std::optional<std::string> config_file_of_header(const std::string& line) {
  if (!line.starts_with("# ") || !std::string_view(line).substr(2).starts_with(kConfigFileName)) return std::nullopt;
  return line.substr(2);
}

namespace {

/// A file kept in a run's identity by its text: a model's own text (MJCF, URDF, a model file of the
/// diagnosis), not an asset such as a mesh.
bool kept_as_text(const std::filesystem::path& file) {
  return is_model_file_name(file.string()) || is_diagnosis_model_file(file.string());
}

}  // namespace

std::string config_files_text(const std::vector<NamedInput>& files) {
  std::string out;
  for (const NamedInput& file : files) {
    const bool text_file = kept_as_text(file.file);
    check_input_file_as<InputError>(file.file, text_file ? kMaxConfigFileBytes : kMaxDataFileBytes, "a file the config names");
    std::ifstream in(file.file, std::ios::binary);
    std::string text;
    std::uint64_t hash = kFnvOffsetBasis, bytes = 0;
    for (char chunk[1 << 16]; in.read(chunk, sizeof chunk) || in.gcount() > 0;) {
      const std::string_view read(chunk, static_cast<std::size_t>(in.gcount()));
      if (text_file) text += read;
      hash = fnv1a_64(read, hash);
      bytes += read.size();
    }
    if (in.bad()) throw InputError(fmt::format("{}: cannot be read; expected {}", file.file.string(), file.name));
    out += config_file_header(file) + '\n';
    if (text_file) {
      out += text;
      if (!text.empty() && text.back() != '\n') out += '\n';
    } else {
      out += fmt::format("{} bytes, FNV-1a 64 hash {:016x}\n", bytes, hash);
    }
  }
  return out;
}

}  // namespace gpilqg
