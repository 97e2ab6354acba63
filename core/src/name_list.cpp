#include "name_list.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace gpilqg::name_list {

namespace {

std::string cut(std::string_view name) {
  if (name.size() <= kMaxNameChars) return std::string(name);
  return std::string(name.substr(0, kMaxNameChars)) + "...";
}

template <class Name>
std::string bounded(const std::vector<Name>& names, std::string_view separator, bool quote) {
  std::string text;
  const std::size_t shown = std::min(names.size(), kMaxListedNames);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) text += separator;
    text += quote ? name_list::quoted(names[i]) : cut(names[i]);
  }
  if (names.size() > shown) text += fmt::format("{}... and {} more", separator, names.size() - shown);
  return text;
}

}  // namespace

std::string quoted(std::string_view name) { return "'" + cut(name) + "'"; }

std::string quoted_list(const std::vector<std::string>& names) { return bounded(names, ", ", true); }
std::string quoted_list(const std::vector<std::string_view>& names) { return bounded(names, ", ", true); }

std::string plain_list(const std::vector<std::string>& names, std::string_view separator) {
  return bounded(names, separator, false);
}
std::string plain_list(const std::vector<std::string_view>& names, std::string_view separator) {
  return bounded(names, separator, false);
}

}  // namespace gpilqg::name_list
