#pragma once
/// @file plugin.hpp
/// Systems from shared libraries (docs/own-system-plugin.md): `gpilqg COMMAND --plugin LIB.so` loads a
/// library built against the installed gpilqg package, and the systems it registers work in every
/// command like the built-in ones.
///
/// A plugin is a shared library (CMake: add_library(NAME MODULE ...) linked to gpilqg::core) with
/// two C entry points, both defined by the GPILQG_PLUGIN macro below:
///
///   extern "C" std::uint32_t gpilqg_plugin_abi();                    // kPluginAbi of its headers
///   extern "C" void gpilqg_register(gpilqg::PluginRegistrar& registrar);  // registrar.add(entry)...
///
/// Loading (load_plugin) is: dlopen(path, RTLD_LAZY | RTLD_LOCAL); the version check through
/// gpilqg_plugin_abi(), before anything else of the plugin runs; gpilqg_register(), which collects
/// entries; then the collected entries are checked against the registry and each other (a name, a
/// builder, no name taken) and go into SystemRegistry::instance() with the plugin's path as their
/// origin: none of them when a check fails. The gpilqg libraries are shared libraries, so a plugin
/// linked against gpilqg::core and the program that loads it use one libgpilqg_core.so and therefore
/// one registry. A plugin whose registration ran is never unloaded: the registry keeps its builders
/// and effects until the process ends.
///
/// Every failure throws PluginError naming the file: a missing file; a file dlopen refuses (with
/// dlerror's text); a library without the entry points; a plugin built against another gpilqg version
/// (both versions named, nothing of it called); an exception from gpilqg_register (its message); a
/// system name that is already registered (both origins named).

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/version.hpp"

namespace gpilqg {

/// The plugin interface's version: the gpilqg version number (version.hpp). A plugin loads only into
/// the gpilqg it was compiled against, because the classes it shares (SystemEntry, Dynamics, Eigen
/// matrices) have no stable binary layout across versions.
inline constexpr std::uint32_t kPluginAbi = kVersionNumber;

/// "major.minor.patch" of a kPluginAbi value, e.g. 1002 -> "0.1.2".
std::string plugin_abi_version(std::uint32_t abi);

/// A plugin that cannot be used. Bad input for the command line (exit 2); the message names the file.
class PluginError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A loaded plugin: its path and the names of the systems it registered.
struct PluginInfo {
  std::string path;
  std::vector<std::string> systems;
};

/// What a plugin's gpilqg_register receives: it collects the plugin's systems, which the loader
/// registers after gpilqg_register returns.
class PluginRegistrar {
 public:
  explicit PluginRegistrar(std::string origin);

  /// Adds one system. Its origin becomes the plugin's path; everything else is the entry's
  /// (system_registry.hpp: a builder, the effect library, same-physics groups, a default run config).
  void add(SystemEntry entry);

  /// The plugin's path as given to load_plugin, e.g. for messages of the plugin's own.
  const std::string& origin() const { return origin_; }
  /// The entries collected so far.
  const std::vector<SystemEntry>& entries() const { return entries_; }

 private:
  friend PluginInfo load_plugin(const std::filesystem::path& path);
  std::string origin_;
  std::vector<SystemEntry> entries_;
};

/// Loads one plugin and registers its systems. Loading the same file again (same canonical path)
/// returns the first load's info and registers nothing. Thread-safe. Throws PluginError.
PluginInfo load_plugin(const std::filesystem::path& path);

/// load_plugin for each path, in order.
std::vector<PluginInfo> load_plugins(const std::vector<std::string>& paths);

}  // namespace gpilqg

/// Defines a plugin's two entry points; the body that follows receives `registrar`
/// (gpilqg::PluginRegistrar&):
///
///   GPILQG_PLUGIN(registrar) {
///     registrar.add(acrobot_entry());
///   }
#define GPILQG_PLUGIN(registrar)                                                                          \
  static void gpilqg_plugin_register_systems(::gpilqg::PluginRegistrar& registrar);                       \
  extern "C" __attribute__((visibility("default"))) std::uint32_t gpilqg_plugin_abi() {                   \
    return ::gpilqg::kPluginAbi;                                                                          \
  }                                                                                                       \
  extern "C" __attribute__((visibility("default"))) void gpilqg_register(::gpilqg::PluginRegistrar& r) { \
    gpilqg_plugin_register_systems(r);                                                                    \
  }                                                                                                       \
  static void gpilqg_plugin_register_systems(::gpilqg::PluginRegistrar& registrar)
