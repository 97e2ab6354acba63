#include "gpilqg/core/systems.hpp"

#include <stdexcept>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/quadrotor.hpp"

namespace gpilqg {

std::optional<Preset> parse_preset(std::string_view name) {
  if (name == "sim") return Preset::Simulator;
  if (name == "real") return Preset::RealWorld;
  return std::nullopt;
}

std::string_view to_string(Preset preset) { return preset == Preset::Simulator ? "sim" : "real"; }

const std::vector<std::string>& system_names() {
  static const std::vector<std::string> kNames = {"cartpole", "quadrotor"};
  return kNames;
}

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// Looks up `name` among the parameter fields and returns a pointer to it, or throws listing them.
template <typename Fields>
double& field(Fields& fields, const std::string& system, const std::string& name) {
  std::vector<std::string> known;
  for (auto& [field_name, value] : fields) {
    if (field_name == name) return *value;
    known.push_back(field_name);
  }
  throw std::invalid_argument("unknown parameter '" + name + "' for system '" + system +
                              "'; expected one of: " + joined(known));
}

}  // namespace

namespace {

template <typename System, typename Params>
DynamicsPtr build(const Params& params, const ActuatorNoise& noise) {
  auto system = std::make_shared<System>(params);
  system->set_noise_model(noise);
  return system;
}

}  // namespace

DynamicsPtr make_system(std::string_view name, Preset preset,
                        const std::map<std::string, double>& overrides, const ActuatorNoise& noise) {
  if (name == "cartpole") {
    auto p = preset == Preset::Simulator ? CartPoleParameters::simulator() : CartPoleParameters::real_world();
    std::vector<std::pair<std::string, double*>> fields = {{"cart_mass", &p.cart_mass},
                                                           {"pole_mass", &p.pole_mass},
                                                           {"pole_length", &p.pole_length},
                                                           {"gravity", &p.gravity}};
    for (const auto& [key, value] : overrides) field(fields, "cartpole", key) = value;
    return build<CartPole>(p, noise);
  }
  if (name == "quadrotor") {
    auto p = preset == Preset::Simulator ? QuadrotorParameters::simulator() : QuadrotorParameters::real_world();
    std::vector<std::pair<std::string, double*>> fields = {
        {"mass", &p.mass}, {"kv", &p.kv},   {"km", &p.km},
        {"inertia", &p.inertia}, {"rho", &p.rho}, {"gravity", &p.gravity}};
    for (const auto& [key, value] : overrides) field(fields, "quadrotor", key) = value;
    return build<Quadrotor>(p, noise);
  }
  throw std::invalid_argument("unknown system '" + std::string(name) + "'; expected one of: " +
                              joined(system_names()));
}

SystemSignature system_signature(std::string_view name) {
  return make_system(name)->signature();
}

}  // namespace gpilqg
