#include "user_effects_file.hpp"

#include <fmt/format.h>

#include "gpilqg/core/limits.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg::diagnosis {

namespace {

/// An array of strings at `path` (required unless `optional`), each entry checked to be a string.
std::vector<std::string> strings(const TomlFields& fields, const toml::table& entry, const std::string& path,
                                 const std::string& key, bool optional) {
  const toml::node* node = entry.get(key);
  if (node == nullptr) {
    if (optional) return {};
    fields.fail(path, "missing; expected an array of strings, e.g. [\"q^3\"]");
  }
  const toml::array* array = node->as_array();
  if (array == nullptr) fields.fail(path, "is not an array; expected an array of strings, e.g. [\"q^3\"]");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < array->size(); ++i) out.push_back(fields.string(fmt::format("{}[{}]", path, i)));
  return out;
}

/// `s` as a TOML basic string, with quotes, backslashes and control characters escaped.
std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string toml_strings(const std::vector<std::string>& list) {
  std::string out;
  for (const auto& s : list) out += (out.empty() ? "" : ", ") + toml_string(s);
  return "[" + out + "]";
}

}  // namespace

std::vector<LibraryEffect> read_user_effects(const toml::table& root, const std::filesystem::path& file,
                                             const std::string& system) {
  const TomlFields fields(root, file);
  const toml::node* node = root.get("user_effects");
  if (node == nullptr) return {};
  const toml::array* array = node->as_array();
  if (array == nullptr || !array->is_array_of_tables())
    fields.fail("user_effects", "is not an array of tables; expected [[user_effects]] entries with name, coordinate and terms");
  if (static_cast<long>(array->size()) > limits::kMaxUserEffects)
    fields.fail("user_effects", fmt::format("has {} entries; expected at most {} (the limit of declared effects)",
                                            array->size(), limits::kMaxUserEffects));
  std::vector<LibraryEffect> out;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const std::string at = fmt::format("user_effects[{}]", i);
    const toml::table& entry = *(*array)[i].as_table();
    fields.only_keys(at, {"name", "coordinate", "terms", "parameters", "units", "v0"});
    for (const char* key : {"name", "coordinate", "terms"})
      if (entry.get(key) == nullptr)
        fields.fail(at, fmt::format("has no '{}'; expected name, coordinate and terms (parameters, units and v0 optional)", key));
    BasisForceDeclaration d;
    d.name = fields.string(at + ".name");
    d.coordinate = fields.string(at + ".coordinate");
    d.terms = strings(fields, entry, at + ".terms", "terms", false);
    d.parameters = strings(fields, entry, at + ".parameters", "parameters", true);
    d.units = strings(fields, entry, at + ".units", "units", true);
    if (entry.get("v0") != nullptr) d.v0 = fields.number(at + ".v0");
    for (std::size_t j = 0; j < out.size(); ++j)
      if (out[j].name == d.name)
        fields.fail(at + ".name", fmt::format("'{}' is declared twice (also user_effects[{}]); expected a name of its own", d.name, j));
    try {
      out.push_back(user_effect_entry(system, d));
    } catch (const DeclarationError& e) {
      const std::string field = at + "." + e.field() + (e.index() >= 0 ? fmt::format("[{}]", e.index()) : "");
      fields.fail(field, e.what());
    }
  }
  return out;
}

std::string user_effects_text(const ModelSpec& model) {
  std::string out;
  for (const LibraryEffect& effect : model.user_effects) {
    const BasisForceDeclaration* d = user_declaration(effect);
    if (d == nullptr)
      throw std::invalid_argument(fmt::format("user effect '{}' is not a declared basis force; a model file cannot hold it", effect.name));
    out += fmt::format("\n[[user_effects]]   # {}\nname = {}\ncoordinate = {}\nterms = {}\n", effect.formula,
                       toml_string(d->name), toml_string(d->coordinate), toml_strings(d->terms));
    if (!d->parameters.empty()) out += fmt::format("parameters = {}\n", toml_strings(d->parameters));
    if (!d->units.empty()) out += fmt::format("units = {}\n", toml_strings(d->units));
    if (d->v0) out += fmt::format("v0 = {}\n", *d->v0);
  }
  return out;
}

}  // namespace gpilqg::diagnosis
