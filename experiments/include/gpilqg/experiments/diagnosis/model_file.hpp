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
/// [[user_effects]]           # optional, repeatable: forces declared without C++ (basis_force.hpp)
/// name = "cart_spring"       # a letter, then letters, digits, '_'; not a library effect's name
/// coordinate = "x"           # a generalised coordinate: cart-pole x, theta; quadrotor px, py, pz, rx,
///                            # ry, rz; a MuJoCo joint's or a plugin's coordinate (or its force, "Q_x")
/// terms = ["q^3"]            # Q_coordinate = sum_k theta_k b_k(q, qdot, u), b_k one of the basis
///                            # qdot, tanh(qdot/v0), qdot*abs(qdot), q, q^2, q^3, sin(q), cos(q), u, 1,
///                            # or a product "a*b" of two; "u:<control>" when there are several controls
/// parameters = ["k3"]        # optional: one name per term (default c1, c2, ...)
/// units = ["N/m^3"]          # optional: one unit per term (default: the force's unit over the term's)
/// v0 = 0.05                  # optional, only with a tanh(qdot/v0) term: its scale (> 0, default 0.05)
///
/// [effects]                  # optional: library or declared effects and their values
/// cart_coulomb_friction = 0.98          # one-parameter effects: a number
/// actuator_gain = { k = 1.1 }           # or a table of the parameters by name
/// cart_spring = -30.0                   # a declared effect, like a library one
/// ```
/// A declared effect is a candidate of the diagnosis beside the library (candidate_effects): it is
/// ranked, `--add` takes it, and `--write-model` writes its declaration back, used or not.
/// Every error is an InputError naming the file, the line and the field, and listing the valid choices,
/// e.g. "m.toml:line 6: field 'user_effects[0].terms[0]': term 'q^4': unknown factor 'q^4'; expected
/// one of the basis qdot, ...".

#include <filesystem>
#include <string>
#include <vector>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg::diagnosis {

/// Reads a model file. `system` is the system it is used for (the command's --system, a config's
/// [system] name), named `system_origin` in the error when the file's [model] system differs.
ModelSpec read_model_file(const std::filesystem::path& file, const std::string& system,
                          const std::string& system_origin = "--system");

/// The same from the text model_file_text wrote (e.g. kept in a result file); `source` names it in errors.
ModelSpec parse_model_text(const std::string& text, const std::string& source, const std::string& system);

/// The TOML text of a model (the format above), preceded by `comment` lines written as "# ...".
std::string model_file_text(const ModelSpec& model, const std::vector<std::string>& comment = {});

/// Writes model_file_text to `file` atomically.
void write_model_file(const std::filesystem::path& file, const ModelSpec& model, const std::vector<std::string>& comment = {});

/// Parses "EFFECT" or "EFFECT=VALUE" for `model`: EFFECT is one of candidate_effects(model) (the
/// library, then the model's user effects). Throws InputError naming `option` (e.g. "--add"), the text
/// and the valid effect names, or saying why VALUE is not acceptable.
EffectRequest parse_add_option(const std::string& text, const ModelSpec& model, const std::string& option = "--add");
/// The same for the bare preset of `system` (the library's effects only).
EffectRequest parse_add_option(const std::string& text, const std::string& system, const std::string& option = "--add");

}  // namespace gpilqg::diagnosis
