// A plugin as if built against the next minor gpilqg version: the loader must refuse it on the
// version number alone and never call its registration, which would abort the test.
#include <cstdint>
#include <cstdlib>

#include "gpilqg/core/plugin.hpp"

extern "C" __attribute__((visibility("default"))) std::uint32_t gpilqg_plugin_abi() {
  return gpilqg::kPluginAbi + 1'000u;
}

extern "C" __attribute__((visibility("default"))) void gpilqg_register(gpilqg::PluginRegistrar&) { std::abort(); }
