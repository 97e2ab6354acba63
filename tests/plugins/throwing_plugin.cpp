// A plugin whose registration fails after adding one system: the loader reports the message and
// registers nothing of it.
#include <stdexcept>

#include "gpilqg/core/plugin.hpp"

GPILQG_PLUGIN(registrar) {
  gpilqg::SystemEntry entry;
  entry.name = "pendulum";
  entry.build = [](gpilqg::Preset, const std::map<std::string, double>&, const gpilqg::ActuatorNoise&) {
    return gpilqg::DynamicsPtr();
  };
  registrar.add(entry);
  throw std::runtime_error("pendulum: calibration file 'pendulum.yaml' not found");
}
