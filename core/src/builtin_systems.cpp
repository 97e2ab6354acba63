#include "builtin_systems.hpp"

#include <stdexcept>
#include <utility>

#include "embedded_run_configs.hpp"
#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/effect_builders.hpp"
#include "gpilqg/core/quadrotor.hpp"

namespace gpilqg {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Sets the overridden fields by name, or throws listing the known names.
void apply_overrides(const std::string& system, const std::vector<std::pair<std::string, double*>>& fields,
                     const std::map<std::string, double>& overrides) {
  for (const auto& [key, value] : overrides) {
    double* target = nullptr;
    std::vector<std::string> known;
    for (const auto& [name, field] : fields) {
      if (name == key) target = field;
      known.push_back(name);
    }
    if (target == nullptr)
      throw std::invalid_argument("unknown parameter '" + key + "' for system '" + system +
                                  "'; expected one of: " + joined(known));
    *target = value;
  }
}

template <typename System, typename Params>
DynamicsPtr with_noise(const Params& params, const ActuatorNoise& noise) {
  auto system = std::make_shared<System>(params);
  system->set_noise_model(noise);
  return system;
}

DynamicsPtr build_cartpole(Preset preset, const std::map<std::string, double>& overrides, const ActuatorNoise& noise) {
  auto p = preset == Preset::Simulator ? CartPoleParameters::simulator() : CartPoleParameters::real_world();
  apply_overrides("cartpole",
                  {{"cart_mass", &p.cart_mass}, {"pole_mass", &p.pole_mass}, {"pole_length", &p.pole_length},
                   {"gravity", &p.gravity}},
                  overrides);
  return with_noise<CartPole>(p, noise);
}

DynamicsPtr build_quadrotor(Preset preset, const std::map<std::string, double>& overrides, const ActuatorNoise& noise) {
  auto p = preset == Preset::Simulator ? QuadrotorParameters::simulator() : QuadrotorParameters::real_world();
  apply_overrides("quadrotor",
                  {{"mass", &p.mass}, {"kv", &p.kv}, {"km", &p.km}, {"inertia", &p.inertia}, {"rho", &p.rho},
                   {"gravity", &p.gravity}},
                  overrides);
  return with_noise<Quadrotor>(p, noise);
}

/// param:<name> for every physical parameter except gravity. Masses, lengths, inertia and rho stay
/// positive; kv and km stay non-negative. Linear: kv, km and rho enter xdot linearly.
void add_recalibrations(const Dynamics& system, std::vector<LibraryEffect>& out) {
  for (const Parameter& p : system.parameters()) {
    if (p.name == "gravity") continue;
    const bool non_negative = p.name == "kv" || p.name == "km";
    const bool linear = p.name == "kv" || p.name == "km" || p.name == "rho";
    out.push_back(recalibration_entry("param:" + p.name, p, non_negative, linear));
  }
}

std::vector<LibraryEffect> cartpole_library() {
  // Q = (Q_x, Q_theta); x = (x, x_dot, theta, theta_dot).
  using namespace effect_bases;
  std::vector<LibraryEffect> out;
  out.push_back(linear_force_entry("cart_viscous_friction", {"b", "N s/m", 1.0, 0.0}, "Q_x = -b x_dot", 2, viscous(0, 1)));
  out.push_back(coulomb_friction_entry("cart_coulomb_friction", {"mu", "N", 1.0, 0.0}, "x", "x_dot", 2, 0, 1));
  out.push_back(linear_force_entry("pole_viscous_damping", {"c", "N m s/rad", 0.1, 0.0}, "Q_theta = -c theta_dot", 2,
                                   viscous(1, 3)));
  out.push_back(coulomb_friction_entry("pole_coulomb_friction", {"tau", "N m", 0.1, 0.0}, "theta", "theta_dot", 2, 1, 3));
  out.push_back(linear_force_entry("external_force_x", {"F", "N", 1.0}, "Q_x = F", 2, constant(0)));
  out.push_back(linear_force_entry("quadratic_drag", {"c_d", "N s^2/m^2", 0.1, 0.0}, "Q_x = -c_d |x_dot| x_dot", 2,
                                   quadratic_drag(1, 1)));
  out.push_back(actuator_gain_entry());
  out.push_back(input_delay_entry());
  add_recalibrations(*build_cartpole(Preset::Simulator, {}, {}), out);
  return out;
}

std::vector<LibraryEffect> quadrotor_library() {
  // Q = (F_x, F_y, F_z, tau_x, tau_y, tau_z); velocities at x(3..5).
  using namespace effect_bases;
  std::vector<LibraryEffect> out;
  const char* axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    out.push_back(linear_force_entry(std::string("external_force_") + axes[i], {"F", "N", 1.0},
                                     std::string("F_") + axes[i] + " = F (world frame)", 6, constant(i)));
  out.push_back(linear_force_entry("quadratic_drag", {"c_d", "N s^2/m^2", 0.1, 0.0}, "F_i = -c_d |v_i| v_i (world frame)", 6,
                                   quadratic_drag(3, 3)));
  out.push_back(actuator_gain_entry());
  out.push_back(input_delay_entry());
  add_recalibrations(*build_quadrotor(Preset::Simulator, {}, {}), out);
  return out;
}

}  // namespace

std::vector<SystemEntry> builtin_system_entries() {
  std::vector<SystemEntry> out(2);
  out[0].name = "cartpole";
  out[0].description = "cart-pole: point mass on a massless pole (sim: pole 1 m, real: 1.3 m)";
  out[0].build = build_cartpole;
  out[0].effects = cartpole_library();
  out[0].same_physics = {{"external_force_x", "constant_force:x"}};
  out[0].default_run_config = embedded::kRunCartpoleToml;
  out[1].name = "quadrotor";
  out[1].description = "quadrotor: van den Berg's model (sim: mass 0.5 kg, real: 0.7 kg)";
  out[1].build = build_quadrotor;
  out[1].effects = quadrotor_library();
  out[1].same_physics = {{"external_force_x", "constant_force:px"},
                         {"external_force_y", "constant_force:py"},
                         {"external_force_z", "constant_force:pz"}};
  out[1].default_run_config = embedded::kRunQuadrotorToml;
  return out;
}

}  // namespace gpilqg
