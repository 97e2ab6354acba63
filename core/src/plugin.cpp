#include "gpilqg/core/plugin.hpp"

#include <dlfcn.h>

#include <map>
#include <mutex>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>

namespace gpilqg {

namespace {

using AbiFunction = std::uint32_t (*)();
using RegisterFunction = void (*)(PluginRegistrar&);

/// The plugins loaded so far, by canonical path. Never destroyed, like the registry that holds their
/// entries.
struct LoadedPlugins {
  std::mutex mutex;
  std::map<std::string, PluginInfo> by_path;
};

LoadedPlugins& loaded_plugins() {
  static auto* plugins = new LoadedPlugins();
  return *plugins;
}

std::string dl_error() {
  const char* text = dlerror();
  return text != nullptr ? text : "unknown dlopen error";
}

/// dlsym's null result is ambiguous (a symbol may be null); dlerror tells whether the lookup failed.
void* find_symbol(void* handle, const char* name) {
  dlerror();
  void* address = dlsym(handle, name);
  return dlerror() == nullptr ? address : nullptr;
}

/// Closes a library none of whose code will run again (its entry points refused it).
struct HandleGuard {
  void* handle;
  ~HandleGuard() {
    if (handle != nullptr) dlclose(handle);
  }
  void release() { handle = nullptr; }
};

/// Refuses, before anything is registered, an entry the registry would refuse: no name, a model
/// file's name, no builder, or a name already taken (by the registry or by an earlier entry of the
/// same plugin, `earlier`). Messages as the registry's own (system_registry.hpp), after the plugin's
/// name.
void check_new_entry(const SystemEntry& entry, const std::vector<std::string>& earlier) {
  const auto refuse = [&](const std::string& why) {
    throw PluginError(fmt::format("plugin '{}': {}", entry.origin, why));
  };
  if (entry.name.empty()) refuse("a system needs a non-empty name");
  if (is_model_file_name(entry.name))
    refuse(fmt::format("'{}' ends like a model file (.xml, .urdf); choose a name without that suffix", entry.name));
  if (!entry.build) refuse(fmt::format("system '{}' has no builder", entry.name));
  for (const std::string& name : earlier)
    if (name == entry.name)
      refuse(fmt::format("system '{}' is registered twice: by {} and by {}", entry.name, entry.origin, entry.origin));
  for (const std::string& name : SystemRegistry::instance().names())
    if (name == entry.name)
      refuse(fmt::format("system '{}' is registered twice: by {} and by {}", entry.name,
                         find_system(name)->origin, entry.origin));
}

}  // namespace

std::string plugin_abi_version(std::uint32_t abi) {
  return fmt::format("{}.{}.{}", abi / 1'000'000u, abi / 1'000u % 1'000u, abi % 1'000u);
}

PluginRegistrar::PluginRegistrar(std::string origin) : origin_(std::move(origin)) {}

void PluginRegistrar::add(SystemEntry entry) {
  entry.origin = origin_;
  entries_.push_back(std::move(entry));
}

PluginInfo load_plugin(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  const std::string shown = path.string();
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  if (ec || !fs::exists(absolute, ec))
    throw PluginError(fmt::format("plugin '{}': no such file (looked for {})", shown, absolute.string()));
  if (!fs::is_regular_file(absolute, ec))
    throw PluginError(fmt::format("plugin '{}': not a file (expected a shared library, LIB.so)", shown));
  const fs::path canonical = fs::canonical(absolute, ec);
  const std::string key = ec ? absolute.string() : canonical.string();

  LoadedPlugins& plugins = loaded_plugins();
  std::lock_guard lock(plugins.mutex);
  if (auto it = plugins.by_path.find(key); it != plugins.by_path.end()) return it->second;

  // A path with a slash: dlopen opens that file and never searches the library path. RTLD_LAZY lets a
  // plugin built against another gpilqg load far enough for its version check to refuse it.
  void* handle = dlopen(key.c_str(), RTLD_LAZY | RTLD_LOCAL);
  if (handle == nullptr) {
    const std::string reason = dl_error();
    const bool missing_symbol = reason.find("undefined symbol") != std::string::npos;
    throw PluginError(fmt::format("plugin '{}' cannot be loaded: {}{}", shown, reason,
                                  missing_symbol ? fmt::format(" (was it built against another gpilqg than {}? "
                                                               "rebuild it against this one)",
                                                               kVersionString)
                                                 : ""));
  }
  HandleGuard guard{handle};

  const auto abi = reinterpret_cast<AbiFunction>(find_symbol(handle, "gpilqg_plugin_abi"));
  if (abi == nullptr)
    throw PluginError(fmt::format(
        "plugin '{}' is not a gpilqg plugin: it exports no gpilqg_plugin_abi() (define the entry points "
        "with GPILQG_PLUGIN from gpilqg/core/plugin.hpp)",
        shown));
  if (const std::uint32_t plugin_abi = abi(); plugin_abi != kPluginAbi)
    throw PluginError(fmt::format(
        "plugin '{}' was built against gpilqg {}, but this is gpilqg {}: rebuild the plugin against this "
        "gpilqg's installed package",
        shown, plugin_abi_version(plugin_abi), kVersionString));
  const auto register_systems = reinterpret_cast<RegisterFunction>(find_symbol(handle, "gpilqg_register"));
  if (register_systems == nullptr)
    throw PluginError(fmt::format(
        "plugin '{}' exports gpilqg_plugin_abi() but no gpilqg_register() (define the entry points with "
        "GPILQG_PLUGIN from gpilqg/core/plugin.hpp)",
        shown));

  // From here on the plugin's code has run and the registrar may hold its objects: never close it.
  guard.release();
  PluginRegistrar registrar(shown);
  try {
    register_systems(registrar);
  } catch (const std::exception& e) {
    throw PluginError(fmt::format("plugin '{}' failed to register its systems: {}", shown, e.what()));
  } catch (...) {
    throw PluginError(
        fmt::format("plugin '{}' failed to register its systems: it threw something that is not a std::exception",
                    shown));
  }

  PluginInfo info{shown, {}};
  for (SystemEntry& entry : registrar.entries_) {
    check_new_entry(entry, info.systems);
    // Build each system once before any is registered, so that a plugin registers all its systems or
    // none (the registry's own check then finds them complete).
    try {
      complete_system_entry(entry);
    } catch (const std::invalid_argument& e) {
      throw PluginError(fmt::format("plugin '{}': {}", shown, e.what()));
    }
    info.systems.push_back(entry.name);
  }
  for (SystemEntry& entry : registrar.entries_) {
    try {
      SystemRegistry::instance().add(std::move(entry));
    } catch (const std::invalid_argument& e) {
      throw PluginError(fmt::format("plugin '{}': {}", shown, e.what()));
    }
  }
  plugins.by_path.emplace(key, info);
  return info;
}

std::vector<PluginInfo> load_plugins(const std::vector<std::string>& paths) {
  std::vector<PluginInfo> out;
  out.reserve(paths.size());
  for (const std::string& path : paths) out.push_back(load_plugin(path));
  return out;
}

}  // namespace gpilqg
