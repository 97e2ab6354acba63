#include "gpilqg/core/quantity.hpp"

namespace gpilqg {

std::vector<std::string> names_of(const std::vector<Quantity>& quantities) {
  std::vector<std::string> names;
  names.reserve(quantities.size());
  for (const auto& q : quantities) names.push_back(q.name);
  return names;
}

int index_of(const std::vector<Quantity>& quantities, const std::string& name) {
  for (std::size_t i = 0; i < quantities.size(); ++i)
    if (quantities[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace gpilqg
