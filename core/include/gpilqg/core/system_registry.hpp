#pragma once
/// @file system_registry.hpp
/// One registry of the systems every command works on (docs/formats.md#systems-and-their-names).
///
/// An entry describes one system completely: how to build it from a preset and named parameter
/// overrides, its presets and parameters, its physical-effects library (when it has a generalised-force
/// map), and its default `gpilqg run` config with tasks (when it has one). The built-in cart-pole and
/// quadrotor are two entries; a plugin (plugin.hpp) adds more; a MuJoCo model file
/// (`--system path/to/model.xml`) becomes an entry the first time its path is resolved.
///
/// The registry is process-wide and thread-safe; entries are immutable once registered, and the
/// systems they build are immutable and shareable between threads (Dynamics' contract).

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {

/// Builds a system: the preset's parameters, then `overrides` by parameter name, then the noise
/// model. Throws std::invalid_argument naming an unknown parameter (with the valid names) or an
/// invalid value.
using SystemBuilder = std::function<DynamicsPtr(Preset preset, const std::map<std::string, double>& overrides,
                                                const ActuatorNoise& noise)>;

/// Everything the commands need to know about one system.
struct SystemEntry {
  std::string name;         ///< the registry name, e.g. "cartpole", or a MuJoCo model's path
  std::string description;  ///< one line for listings, e.g. "cart-pole, point mass on a massless pole"
  SystemBuilder build;      ///< required
  /// The parameter sets build() takes, by name: "sim" (the simulator) and "real" (the world). A model
  /// file has one set, its own, under both names.
  std::vector<std::string> presets = {"sim", "real"};
  /// The named physical parameters with their "sim" values (what `--param` and `param:<name>` accept).
  /// Filled from build() at registration when empty.
  std::vector<Parameter> parameters;
  /// True when the system has a generalised-force map (GeneralisedForceInput), so force effects apply.
  /// Set from build() at registration.
  bool generalised_forces = false;
  /// The effect library in its fixed order (effect_library.hpp); empty when the system has no
  /// generalised-force map and no gain or parameters to recalibrate. Built once, at registration.
  std::vector<LibraryEffect> effects;
  /// Groups of effect names that are the same physics, e.g. {"param:elbow.damping",
  /// "joint_viscous_damping:elbow"}: the diagnosis reports them as aliases of each other and never
  /// ranks them against each other.
  std::vector<std::vector<std::string>> same_physics;
  /// The default `gpilqg run` config (TOML text, with [[tasks]]); empty when the system has none, in
  /// which case `run` needs a complete `--config`.
  std::string default_run_config;
  /// Where the entry came from, for messages: "built-in", a plugin's path, a model file's path.
  std::string origin = "built-in";
};

using SystemEntryPtr = std::shared_ptr<const SystemEntry>;

/// Checks that `entry` builds (its "sim" preset, no overrides, no noise) and fills `parameters` (when
/// empty) and `generalised_forces` from the built system. Throws std::invalid_argument naming the
/// system when the builder fails or returns nothing.
void complete_system_entry(SystemEntry& entry);

/// True when `name` designates a model file rather than a registered name: it ends in ".xml" or
/// ".urdf" (any case). Such names are resolved by loading the file (mujoco_system.hpp).
bool is_model_file_name(std::string_view name);

class SystemRegistry {
 public:
  /// The process-wide registry, holding the built-in systems from its first use.
  static SystemRegistry& instance();

  /// Adds an entry. Throws std::invalid_argument when the name is empty, already registered (naming
  /// both origins), looks like a model file, or the entry has no builder.
  void add(SystemEntry entry);

  /// The entry called `name`; a model file name is loaded on first use and kept. Throws
  /// std::invalid_argument listing the registered names when `name` is unknown, or with the loader's
  /// message when a model file cannot be used.
  SystemEntryPtr find(std::string_view name);

  /// The registered names (built-ins first, then in registration order); model files not included.
  std::vector<std::string> names() const;

 private:
  SystemRegistry();
  struct State;
  std::shared_ptr<State> state_;
};

/// The entry for `name` in the process-wide registry (SystemRegistry::instance().find(name)).
SystemEntryPtr find_system(std::string_view name);

}  // namespace gpilqg
