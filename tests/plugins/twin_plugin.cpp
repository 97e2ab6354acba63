// A plugin that registers a system under a name someone else already uses (GPILQG_TWIN_NAME): a
// built-in's ("cartpole") or the example plugin's ("acrobot").
#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/plugin.hpp"

GPILQG_PLUGIN(registrar) {
  gpilqg::SystemEntry entry;
  entry.name = GPILQG_TWIN_NAME;
  entry.description = "a second system of the same name";
  entry.build = [](gpilqg::Preset, const std::map<std::string, double>&, const gpilqg::ActuatorNoise&) {
    return gpilqg::DynamicsPtr(std::make_shared<gpilqg::CartPole>());
  };
  registrar.add(entry);
}
