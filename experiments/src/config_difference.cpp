#include "config_difference.hpp"

#include <set>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>

#include "gpilqg/experiments/toml_fields.hpp"

namespace gpilqg {
namespace {

/// Same type and same value (tables and arrays deeply).
bool same(const toml::node& a, const toml::node& b) {
  if (a.type() != b.type()) return false;
  return a.visit([&b](const auto& x) {
    using Node = std::remove_cvref_t<decltype(x)>;
    return x == *b.as<Node>();
  });
}

std::string text_of(const toml::node* node) {
  if (!node) return "absent";
  if (node->is_table()) return "a table";
  if (node->is_array_of_tables()) return fmt::format("{} tables", node->as_array()->size());
  std::ostringstream text;
  node->visit([&text](const auto& value) { text << value; });
  return text.str();
}

std::optional<ConfigDifference> difference(const toml::node* a, const toml::node* b, const std::string& path) {
  if (a && b && a->is_table() && b->is_table()) {
    std::set<std::string> keys;
    for (const auto& [key, value] : *a->as_table()) keys.insert(std::string(key.str()));
    for (const auto& [key, value] : *b->as_table()) keys.insert(std::string(key.str()));
    for (const std::string& key : keys) {
      const std::string field = path.empty() ? toml_key(key) : path + "." + toml_key(key);
      if (auto found = difference(a->as_table()->get(key), b->as_table()->get(key), field)) return found;
    }
    return std::nullopt;
  }
  if (a && b && a->is_array_of_tables() && b->is_array_of_tables() && a->as_array()->size() == b->as_array()->size()) {
    for (std::size_t i = 0; i < a->as_array()->size(); ++i)
      if (auto found = difference(a->as_array()->get(i), b->as_array()->get(i), fmt::format("{}[{}]", path, i)))
        return found;
    return std::nullopt;
  }
  if (a && b && same(*a, *b)) return std::nullopt;
  return ConfigDifference{path, text_of(a), text_of(b)};
}

}  // namespace

std::optional<ConfigDifference> config_difference(const toml::table& a, const toml::table& b) {
  return difference(&a, &b, "");
}

}  // namespace gpilqg
