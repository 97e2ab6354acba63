#pragma once
/// @file toml_fields.hpp
/// Strict reading of TOML configs: every lookup names the file, the line and the dotted field in its
/// error, unknown keys are rejected (nothing is silently ignored), and numbers must be finite.
/// Shared by every command that reads a config (solve, run, diagnose).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// `key` as a TOML key: bare when it is made of letters, digits, '_' and '-', else quoted (names
/// such as "elbow.damping" or "joint_viscous_damping:elbow"). TomlFields paths accept quoted keys.
std::string toml_key(const std::string& key);

class TomlFields {
 public:
  /// Parses `file`; a syntax error becomes an InputError "<file>:line N: <what>". First the file must be
  /// a readable regular file of at most kMaxConfigFileBytes (check_input_file_as, input_file.hpp), else
  /// an InputError "<file>: <problem>; expected a TOML config" (no such file, a FIFO, too large, ...).
  static toml::table parse(const std::filesystem::path& file);
  /// Parses TOML text; `source` names it in errors (and in the nodes' source regions).
  static toml::table parse_text(const std::string& text, const std::string& source);
  /// Completes `overrides` with `base` (the defaults): tables merge key by key, every other value the
  /// user gave (arrays included) replaces the default. A key `base` does not have is an InputError
  /// naming the overriding source, its line and the keys that exist there. The user's nodes are kept
  /// in place, so later errors still name their file and line. `optional` lists the dotted paths the
  /// user may give although `base` has no default for them (e.g. "system.model", "world").
  static void merge(toml::table& overrides, const toml::table& base, const std::vector<std::string>& optional = {});

  TomlFields(const toml::table& root, std::filesystem::path file) : root_(root), file_(std::move(file)) {}

  /// Throws unless every key of table `section` (or the root when empty) is in `allowed`.
  void only_keys(const std::string& section, const std::vector<std::string>& allowed) const;
  /// Throws when a required section is missing.
  void require_section(const std::string& section) const;

  std::string string(const std::string& path, std::optional<std::string> fallback = std::nullopt) const;
  bool boolean(const std::string& path, std::optional<bool> fallback = std::nullopt) const;
  double number(const std::string& path, std::optional<double> fallback = std::nullopt) const;
  long integer(const std::string& path, std::optional<long> fallback = std::nullopt) const;
  /// An integer within [min, max], as int (min and max must fit an int): a value outside fails naming
  /// the field and the range, instead of being cut to an int.
  int integer_in(const std::string& path, int min, int max, std::optional<int> fallback = std::nullopt) const;
  /// An array of numbers; `size` >= 0 requires that many entries.
  Vector vector(const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) const;
  /// A state-valued array (an initial state, a goal, a state noise std): vector(), and every entry
  /// within |x_i| <= kDivergedStateMagnitude (1e12, control/rollout.hpp). A state beyond that bound
  /// counts as diverged everywhere else (rollouts, the DDP line search, the diagnosis), so a config
  /// that starts there is bad input: "field 'problem.x0': entry 0 is 1e+300; expected |value| <= 1e+12".
  Vector state_vector(const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) const;
  /// An initial control (u_init), bounded the same way: a control beyond 1e12 drives every model past
  /// the divergence bound at the first step, and its quadratic cost overflows.
  Vector control_vector(const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) const;
  /// The diagonal of a cost weight matrix (Q, R, Qf): vector(), and every entry within
  /// [0, kMaxCostWeight] (1e150, core/limits.hpp), so that the cost of any trajectory within the
  /// divergence bound stays finite: "field 'problem.Qf': entry 0 is 1e+308; expected a weight in
  /// [0, 1e+150] (...)".
  Vector weight_vector(const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) const;
  bool has(const std::string& path) const;
  /// A file named by the string field at `path`: a relative path is relative to the folder of the
  /// config file that holds the field.
  std::filesystem::path file_path(const std::string& path) const;
  /// A system's name (docs/formats.md, "Systems and their names") as the registry resolves it: a MuJoCo model file
  /// given by a relative path is relative to the config file's folder. Fails naming the field for an
  /// unknown system or a model file that cannot be loaded.
  std::string system_name(const std::string& path) const;
  /// The signature of system_name(path); fails like it.
  SystemSignature system(const std::string& path) const;
  /// "euler" or "rk4".
  Integrator integrator(const std::string& path, std::optional<std::string> fallback = std::nullopt) const;
  /// For a system with its own integrator (a MuJoCo model, whose integrator and timestep are the
  /// simulator) fails when `integrator_path` or `substeps_path` is given, and returns true; false
  /// for every other system.
  bool own_integrator(const std::string& system_name, const std::string& integrator_path,
                      const std::string& substeps_path) const;

  /// "<file>:line N: field 'a.b': <problem>" (line when the node is known).
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const;

 private:
  const toml::node* find(const std::string& path) const;
  /// Fails naming the first entry of `v` with |v_i| > kDivergedStateMagnitude; `why` ends the message.
  void check_bound(const std::string& path, const Vector& v, const char* why) const;
  /// The file a node was read from (its source region), else the file this reader was made for.
  std::string source_of(const toml::node* node) const;
  const toml::table& root_;
  std::filesystem::path file_;
};

}  // namespace gpilqg
