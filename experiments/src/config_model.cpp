#include "gpilqg/experiments/config_model.hpp"

#include <fmt/format.h>

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

}  // namespace gpilqg
