#include "gpilqg/gp/backend_registry.hpp"

#include <algorithm>
#include <functional>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gpilqg/gp/compact.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace gpilqg::gp {
namespace {

using Factory = std::function<std::unique_ptr<GpBackend>(const BackendSettings&)>;

struct RegistryEntry {
  std::string_view name;
  Factory make;
};

const std::vector<RegistryEntry>& registry() {
  static const std::vector<RegistryEntry> entries = {
      {"exact",
       [](const BackendSettings& s) -> std::unique_ptr<GpBackend> {
         ExactGpOptions options;
         options.max_training_points = s.exact_points;
         options.threads = s.threads;
         return std::make_unique<ExactGpBackend>(options);
       }},
      {"fitc",
       [](const BackendSettings& s) -> std::unique_ptr<GpBackend> {
         FitcOptions options;
         options.inducing = s.inducing;
         options.threads = s.threads;
         return std::make_unique<FitcBackend>(options);
       }},
      {"ssgp",
       [](const BackendSettings& s) -> std::unique_ptr<GpBackend> {
         SsgpOptions options;
         options.frequencies = s.frequencies;
         options.threads = s.threads;
         return std::make_unique<SsgpBackend>(options);
       }},
      {"compact",
       [](const BackendSettings& s) -> std::unique_ptr<GpBackend> {
         CompactOptions options;
         options.initial_neighbours = s.compact_neighbours;
         options.max_neighbours = s.compact_max_neighbours;
         options.threads = s.threads;
         return std::make_unique<CompactBackend>(options);
       }},
  };
  return entries;
}

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

}  // namespace

void BackendSettings::validate() const {
  auto positive = [](int value, const char* field) {
    if (value < 1) throw std::invalid_argument(fmt::format("backend settings: {} must be >= 1, got {}", field, value));
  };
  positive(exact_points, "exact_points");
  positive(inducing, "inducing");
  positive(frequencies, "frequencies");
  positive(compact_neighbours, "compact_neighbours");
  if (compact_max_neighbours < compact_neighbours)
    throw std::invalid_argument(fmt::format("backend settings: compact_max_neighbours = {} must be >= compact_neighbours = {}",
                                            compact_max_neighbours, compact_neighbours));
  positive(threads, "threads");
}

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.emplace_back(entry.name);
  return names;
}

std::vector<std::string> backends_taking_known_noise() {
  std::vector<std::string> names;
  for (const auto& entry : registry())
    if (entry.make(BackendSettings{})->takes_known_noise()) names.emplace_back(entry.name);
  return names;
}

std::unique_ptr<GpBackend> make_backend(std::string_view name, const BackendSettings& settings) {
  settings.validate();
  for (const auto& entry : registry())
    if (entry.name == name) return entry.make(settings);
  throw std::invalid_argument(
      fmt::format("unknown GP backend '{}' (known: {})", name, fmt::join(backend_names(), ", ")));
}

std::vector<std::string> parse_backend_list(std::string_view list) {
  std::vector<std::string> names;
  const auto known = backend_names();
  std::size_t start = 0;
  while (start <= list.size()) {
    const auto comma = list.find(',', start);
    const auto end = comma == std::string_view::npos ? list.size() : comma;
    const std::string name(trim(list.substr(start, end - start)));
    if (name.empty())
      throw std::invalid_argument(fmt::format("backend list '{}': empty entry (expected names from: {})", list,
                                              fmt::join(known, ", ")));
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw std::invalid_argument(
          fmt::format("backend list '{}': unknown backend '{}' (known: {})", list, name, fmt::join(known, ", ")));
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw std::invalid_argument(fmt::format("backend list '{}': '{}' is given twice", list, name));
    names.push_back(name);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return names;
}

}  // namespace gpilqg::gp
