#pragma once
/// @file diagnose_request.hpp
/// What `gpilqg diagnose` is asked, in the terms of its options: the command line and the Python
/// package fill the same request, so both have the same defaults and the same error messages.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpilqg/experiments/diagnosis/diagnosis.hpp"

namespace gpilqg::diagnosis {

struct DiagnoseRequest {
  std::string system;
  std::string model_file;        ///< a model file (TOML); empty: `preset`
  std::string preset = "sim";
  std::vector<std::string> add;  ///< EFFECT or EFFECT=VALUE
  bool auto_select = false;      ///< --auto: several effects
  /// --search: how --auto searches, "subsets" (when not given) or "forward"; only with --auto.
  std::optional<std::string> search;
  std::string integrator = "rk4";
  double heldout = 0.3;          ///< fraction of the episodes held out
  std::vector<int> horizons = {1, 10, 50};  ///< k of the k-step predictions (distinct, >= 1)
  int gp_points = 300;           ///< GP training points per state
  int gp_restarts = 1;
  std::string backend = "exact";
  std::uint64_t seed = 1;
  /// --criterion: the error effects are fitted to and scored on, "one-step", "simulation" or
  /// "inverse-dynamics" (fit_criterion.hpp), or "auto": chosen from the data (criterion_choice.hpp).
  std::string criterion = "auto";
  /// --window: samples per simulation window; required with "simulation", not accepted with "one-step".
  std::optional<long> window;
  /// --exclude: candidate effects never ranked, searched or proposed, each a name or a shell pattern
  /// over the candidates' names (`*` any text, `?` one character, `[...]` a set), e.g.
  /// `param:*.armature` (every armature), `*:wrist*` (every effect of the wrist's joints, actuators and
  /// bodies), `actuator_gain:*`.
  std::vector<std::string> exclude;
  /// --include: candidates searched only on request (LibraryEffect::on_request, e.g. the bodies'
  /// second moments) to rank and search too, each a name or a pattern as for --exclude.
  std::vector<std::string> include;
};

/// The candidate effects of `model` that the --exclude patterns name, in the candidates' order.
/// Throws InputError naming the pattern when it matches no candidate (listing them), and naming the
/// effect when an --add effect (`add`) is excluded.
std::vector<std::string> excluded_effects(const std::vector<std::string>& patterns, const ModelSpec& model,
                                          const std::vector<std::string>& add = {});

/// The candidates of `model` searched only on request (LibraryEffect::on_request) that the --include
/// patterns name and `excluded` does not, in the candidates' order. Throws InputError naming the
/// pattern when it matches no such candidate (listing them), or only excluded ones.
std::vector<std::string> included_effects(const std::vector<std::string>& patterns, const ModelSpec& model,
                                          const std::vector<std::string>& excluded);

/// At most this many k-step horizons (each stores its windows' predictions in the report).
inline constexpr std::size_t kMaxHorizonCount = 32;

/// The diagnosis options of a request. Throws InputError naming the option (`--preset`, `--add`,
/// `--search`, `--integrator`, `--heldout`, `--horizons`, `--gp-points`, `--gp-restarts`, `--backend`,
/// `--criterion`, `--window`) or the model file.
DiagnosisOptions diagnosis_options(const DiagnoseRequest& request);

}  // namespace gpilqg::diagnosis
