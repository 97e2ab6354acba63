#include "gpilqg/core/system_registry.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>

#include "builtin_systems.hpp"
#include "gpilqg/core/effect_builders.hpp"
#include "gpilqg/core/generalised_forces.hpp"
#include "gpilqg/core/mujoco_system.hpp"

namespace gpilqg {

bool is_model_file_name(std::string_view name) {
  const auto ends_with = [&](std::string_view suffix) {
    if (name.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), name.rbegin(),
                      [](char s, char n) { return std::tolower(static_cast<unsigned char>(n)) == s; });
  };
  return ends_with(".xml") || ends_with(".urdf");
}

void complete_system_entry(SystemEntry& entry) {
  DynamicsPtr probe;
  try {
    probe = entry.build(Preset::Simulator, {}, {});
  } catch (const std::exception& e) {
    throw std::invalid_argument(fmt::format("system '{}' ({}) cannot be built: {}", entry.name, entry.origin, e.what()));
  }
  if (!probe) throw std::invalid_argument(fmt::format("system '{}' ({}): its builder returned nothing", entry.name, entry.origin));
  if (entry.parameters.empty()) entry.parameters = probe->parameters();
  if (probe->control_dim() == 0) {
    // A passive system (no controls): effects of the input (actuator_gain, input_delay) cannot apply.
    std::erase_if(entry.effects, [](const LibraryEffect& e) {
      return e.kind == EffectKind::ActuatorGain || e.kind == EffectKind::InputDelay;
    });
  }
  const auto* forces = dynamic_cast<const GeneralisedForceInput*>(probe.get());
  entry.generalised_forces = forces != nullptr;
  if (forces == nullptr) return;
  // A constant generalised force on every coordinate: an offset almost every real machine has.
  const auto components = static_cast<int>(forces->generalised_forces().size());
  for (const GeneralisedCoordinate& c : generalised_coordinates(*probe)) {
    const std::string name = "constant_force:" + c.name;
    if (std::any_of(entry.effects.begin(), entry.effects.end(), [&](const LibraryEffect& e) { return e.name == name; }))
      continue;
    entry.effects.push_back(constant_force_entry(c.name, c.force,
                                                 forces->generalised_forces()[static_cast<std::size_t>(c.component)].unit,
                                                 components, c.component));
  }
}

struct SystemRegistry::State {
  mutable std::mutex mutex;
  std::vector<SystemEntryPtr> entries;                   ///< registered names, in order
  std::map<std::string, SystemEntryPtr> model_files;     ///< loaded model files by canonical path
};

SystemRegistry::SystemRegistry() : state_(std::make_shared<State>()) {}

SystemRegistry& SystemRegistry::instance() {
  static SystemRegistry* registry = [] {
    auto* r = new SystemRegistry();  // never destroyed: plugins may hold entries until exit
    for (SystemEntry& entry : builtin_system_entries()) r->add(std::move(entry));
    return r;
  }();
  return *registry;
}

void SystemRegistry::add(SystemEntry entry) {
  if (entry.name.empty()) throw std::invalid_argument("system registry: a system needs a non-empty name");
  if (is_model_file_name(entry.name))
    throw std::invalid_argument(fmt::format(
        "system registry: '{}' ends like a model file (.xml, .urdf); choose a name without that suffix", entry.name));
  if (!entry.build) throw std::invalid_argument(fmt::format("system registry: system '{}' has no builder", entry.name));
  complete_system_entry(entry);
  std::lock_guard lock(state_->mutex);
  for (const auto& e : state_->entries)
    if (e->name == entry.name)
      throw std::invalid_argument(fmt::format("system '{}' is registered twice: by {} and by {}", entry.name, e->origin,
                                              entry.origin));
  state_->entries.push_back(std::make_shared<const SystemEntry>(std::move(entry)));
}

SystemEntryPtr SystemRegistry::find(std::string_view name) {
  if (is_model_file_name(name)) {
    std::error_code ec;
    const std::filesystem::path path(name);
    const auto canonical = std::filesystem::weakly_canonical(path, ec);
    const std::string key = ec ? std::string(name) : canonical.string();
    std::lock_guard lock(state_->mutex);
    if (auto it = state_->model_files.find(key); it != state_->model_files.end()) return it->second;
    auto entry = std::make_shared<const SystemEntry>(mujoco_system_entry(std::string(name)));
    state_->model_files.emplace(key, entry);
    return entry;
  }
  std::lock_guard lock(state_->mutex);
  for (const auto& e : state_->entries)
    if (e->name == name) return e;
  std::string known;
  for (const auto& e : state_->entries) known += (known.empty() ? "" : ", ") + e->name;
  throw std::invalid_argument(fmt::format(
      "unknown system '{}'; expected one of: {}, or a MuJoCo model file (.xml), or a system of a --plugin", name, known));
}

std::vector<std::string> SystemRegistry::names() const {
  std::lock_guard lock(state_->mutex);
  std::vector<std::string> out;
  for (const auto& e : state_->entries) out.push_back(e->name);
  return out;
}

SystemEntryPtr find_system(std::string_view name) { return SystemRegistry::instance().find(name); }

}  // namespace gpilqg
