/// The acrobot as a gpilqg plugin: `gpilqg COMMAND --plugin libacrobot.so --system acrobot ...`.
///
/// The registry entry holds the builder (a preset's parameters, then overrides by name, then the
/// noise model) and the effect library the diagnosis searches:
///
/// | name                                   | parameter     | enters as                           |
/// |----------------------------------------|---------------|-------------------------------------|
/// | joint_viscous_damping:theta1, :theta2  | b [N m s/rad] | Q_j = -b theta_j_dot                |
/// | joint_coulomb_friction:theta1, :theta2 | tau [N m]     | Q_j = -tau tanh(theta_j_dot / v0)   |
/// | actuator_gain                          | k [-]         | the applied torque is k tau         |
/// | param:<name>                           | the value     | recalibrates a mass or a length     |

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <gpilqg/core/effect_builders.hpp>
#include <gpilqg/core/plugin.hpp>

#include "acrobot.hpp"

namespace acrobot {

namespace {

using gpilqg::LibraryEffect;

/// Sets the overridden parameters by name, or throws listing the known names.
void apply_overrides(AcrobotParameters& p, const std::map<std::string, double>& overrides) {
  const std::map<std::string, double*> fields = {{"link1_mass", &p.link1_mass},
                                                 {"link2_mass", &p.link2_mass},
                                                 {"link1_length", &p.link1_length},
                                                 {"link2_length", &p.link2_length},
                                                 {"gravity", &p.gravity}};
  for (const auto& [name, value] : overrides) {
    const auto field = fields.find(name);
    if (field == fields.end())
      throw std::invalid_argument("unknown parameter '" + name +
                                  "' for system 'acrobot'; expected one of: link1_mass, link2_mass, link1_length, "
                                  "link2_length, gravity");
    *field->second = value;
  }
}

gpilqg::DynamicsPtr build_acrobot(gpilqg::Preset preset, const std::map<std::string, double>& overrides,
                                  const gpilqg::ActuatorNoise& noise) {
  AcrobotParameters p =
      preset == gpilqg::Preset::Simulator ? AcrobotParameters::simulator() : AcrobotParameters::real_world();
  apply_overrides(p, overrides);
  auto system = std::make_shared<Acrobot>(p);
  system->set_noise_model(noise);
  return system;
}

/// Q = (Q_theta1, Q_theta2); x = (theta1, theta2, theta1_dot, theta2_dot).
std::vector<LibraryEffect> acrobot_effects() {
  using namespace gpilqg::effect_bases;
  std::vector<LibraryEffect> out;
  for (int joint = 0; joint < 2; ++joint) {
    const std::string q = "theta" + std::to_string(joint + 1);
    out.push_back(gpilqg::linear_force_entry("joint_viscous_damping:" + q, {"b", "N m s/rad", 0.1},
                                             "Q_" + q + " = -b " + q + "_dot", 2, viscous(joint, joint + 2)));
  }
  for (int joint = 0; joint < 2; ++joint) {
    const std::string q = "theta" + std::to_string(joint + 1);
    out.push_back(gpilqg::coulomb_friction_entry("joint_coulomb_friction:" + q, {"tau", "N m", 0.1}, q, q + "_dot", 2,
                                                 joint, joint + 2));
  }
  out.push_back(gpilqg::actuator_gain_entry());
  out.push_back(gpilqg::input_delay_entry());
  // Masses and lengths stay positive; xdot is not linear in any of them (they enter through M^-1).
  for (const gpilqg::Parameter& p : Acrobot().parameters())
    if (p.name != "gravity") out.push_back(gpilqg::recalibration_entry("param:" + p.name, p, false, false));
  return out;
}

gpilqg::SystemEntry acrobot_entry() {
  gpilqg::SystemEntry entry;
  entry.name = "acrobot";
  entry.description = "acrobot: two rods, torque at the elbow only (sim: 1 kg links, real: second link 1.3 kg)";
  entry.build = build_acrobot;
  entry.effects = acrobot_effects();
  return entry;
}

}  // namespace
}  // namespace acrobot

GPILQG_PLUGIN(registrar) { registrar.add(acrobot::acrobot_entry()); }
