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

#include "gpilqg/core/types.hpp"

namespace gpilqg {

class TomlFields {
 public:
  /// Parses `file`; a syntax error becomes an InputError "<file>:line N: <what>".
  static toml::table parse(const std::filesystem::path& file);
  /// Parses TOML text; `source` names it in errors (and in the nodes' source regions).
  static toml::table parse_text(const std::string& text, const std::string& source);
  /// Overrides `base` with `overrides`: tables merge key by key, every other value (arrays included)
  /// replaces the base's. A key `base` does not have is an InputError naming the overriding source,
  /// its line and the keys that exist there.
  static void merge(toml::table& base, const toml::table& overrides);

  TomlFields(const toml::table& root, std::filesystem::path file) : root_(root), file_(std::move(file)) {}

  /// Throws unless every key of table `section` (or the root when empty) is in `allowed`.
  void only_keys(const std::string& section, const std::vector<std::string>& allowed) const;
  /// Throws when a required section is missing.
  void require_section(const std::string& section) const;

  std::string string(const std::string& path, std::optional<std::string> fallback = std::nullopt) const;
  double number(const std::string& path, std::optional<double> fallback = std::nullopt) const;
  long integer(const std::string& path, std::optional<long> fallback = std::nullopt) const;
  /// An array of numbers; `size` >= 0 requires that many entries.
  Vector vector(const std::string& path, int size, std::optional<Vector> fallback = std::nullopt) const;
  bool has(const std::string& path) const;

  /// "<file>:line N: field 'a.b': <problem>" (line when the node is known).
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const;

 private:
  const toml::node* find(const std::string& path) const;
  /// The file a node was read from (its source region), else the file this reader was made for.
  std::string source_of(const toml::node* node) const;
  const toml::table& root_;
  std::filesystem::path file_;
};

}  // namespace gpilqg
