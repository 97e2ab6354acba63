#include "gpilqg/core/effect_library.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace gpilqg {

namespace {

/// Width of the tanh that smooths Coulomb friction (DESIGN.md section 5) [m/s or rad/s].
constexpr double kCoulombWidth = 0.05;

ForceEffectPtr linear_force(std::string name, EffectParameter parameter, std::string formula, int force_dim,
                            LinearForceEffect::Basis basis) {
  return std::make_shared<LinearForceEffect>(std::move(name), std::move(parameter), std::move(formula), force_dim,
                                             std::move(basis));
}

/// g = -v on component `component`, v = x(velocity).
LinearForceEffect::Basis viscous(int component, int velocity) {
  return [=](const VectorCRef& x, VectorRef g, Matrix* dg_dx) {
    g(component) = -x(velocity);
    if (dg_dx != nullptr) (*dg_dx)(component, velocity) = -1.0;
  };
}

/// g = -tanh(v / w), dg/dv = -(1 - tanh^2) / w.
LinearForceEffect::Basis coulomb(int component, int velocity) {
  return [=](const VectorCRef& x, VectorRef g, Matrix* dg_dx) {
    const double t = std::tanh(x(velocity) / kCoulombWidth);
    g(component) = -t;
    if (dg_dx != nullptr) (*dg_dx)(component, velocity) = -(1.0 - t * t) / kCoulombWidth;
  };
}

/// g = e_component: a constant force.
LinearForceEffect::Basis constant(int component) {
  return [=](const VectorCRef&, VectorRef g, Matrix*) { g(component) = 1.0; };
}

/// g_i = -|v_i| v_i for the velocities starting at `first_velocity`, dg_i/dv_i = -2 |v_i|.
LinearForceEffect::Basis quadratic_drag(int components, int first_velocity) {
  return [=](const VectorCRef& x, VectorRef g, Matrix* dg_dx) {
    for (int i = 0; i < components; ++i) {
      const double v = x(first_velocity + i);
      g(i) = -std::abs(v) * v;
      if (dg_dx != nullptr) (*dg_dx)(i, first_velocity + i) = -2.0 * std::abs(v);
    }
  };
}

LibraryEffect force_entry(ForceEffectPtr force) {
  LibraryEffect e;
  e.name = force->name();
  e.kind = EffectKind::Force;
  e.parameters = force->parameters();
  e.formula = force->formula();
  e.linear = force->linear_in_parameters();
  e.force = std::move(force);
  return e;
}

LibraryEffect gain_entry() {
  LibraryEffect e;
  e.name = "actuator_gain";
  e.kind = EffectKind::ActuatorGain;
  e.parameters = {{"k", "-", 1.0, 0.0, std::numeric_limits<double>::infinity()}};
  e.formula = "applied input = k u";
  e.linear = true;  // the built-in systems are control-affine
  return e;
}

/// param:<name> for every physical parameter except gravity. Masses, lengths, inertia and rho stay
/// positive; kv and km stay non-negative. Linear: kv, km and rho enter xdot linearly.
void add_recalibrations(const Dynamics& system, std::vector<LibraryEffect>& out) {
  for (const Parameter& p : system.parameters()) {
    if (p.name == "gravity") continue;
    LibraryEffect e;
    e.name = "param:" + p.name;
    e.kind = EffectKind::Recalibration;
    e.recalibrated = p.name;
    const bool non_negative = p.name == "kv" || p.name == "km";
    e.parameters = {{p.name, p.unit, std::max(std::abs(p.value), 1e-3), non_negative ? 0.0 : 1e-6 * std::abs(p.value),
                     std::numeric_limits<double>::infinity()}};
    e.formula = "recalibrate " + p.name + " [" + p.unit + "]";
    e.linear = p.name == "kv" || p.name == "km" || p.name == "rho";
    out.push_back(std::move(e));
  }
}

std::vector<LibraryEffect> cartpole_library() {
  // Q = (Q_x, Q_theta); x = (x, x_dot, theta, theta_dot).
  std::vector<LibraryEffect> out;
  out.push_back(force_entry(linear_force("cart_viscous_friction", {"b", "N s/m", 1.0}, "Q_x = -b x_dot", 2, viscous(0, 1))));
  out.push_back(force_entry(linear_force("cart_coulomb_friction", {"mu", "N", 1.0}, "Q_x = -mu tanh(x_dot / 0.05)", 2,
                                         coulomb(0, 1))));
  out.push_back(force_entry(linear_force("pole_viscous_damping", {"c", "N m s/rad", 0.1}, "Q_theta = -c theta_dot", 2,
                                         viscous(1, 3))));
  out.push_back(force_entry(linear_force("pole_coulomb_friction", {"tau", "N m", 0.1},
                                         "Q_theta = -tau tanh(theta_dot / 0.05)", 2, coulomb(1, 3))));
  out.push_back(force_entry(linear_force("external_force_x", {"F", "N", 1.0}, "Q_x = F", 2, constant(0))));
  out.push_back(force_entry(linear_force("quadratic_drag", {"c_d", "N s^2/m^2", 0.1}, "Q_x = -c_d |x_dot| x_dot", 2,
                                         quadratic_drag(1, 1))));
  out.push_back(gain_entry());
  add_recalibrations(*make_system("cartpole"), out);
  return out;
}

std::vector<LibraryEffect> quadrotor_library() {
  // Q = (F_x, F_y, F_z, tau_x, tau_y, tau_z); velocities at x(3..5).
  std::vector<LibraryEffect> out;
  const char* axes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    out.push_back(force_entry(linear_force(std::string("external_force_") + axes[i], {"F", "N", 1.0},
                                           std::string("F_") + axes[i] + " = F (world frame)", 6, constant(i))));
  out.push_back(force_entry(
      linear_force("quadratic_drag", {"c_d", "N s^2/m^2", 0.1}, "F_i = -c_d |v_i| v_i (world frame)", 6, quadratic_drag(3, 3))));
  out.push_back(gain_entry());
  add_recalibrations(*make_system("quadrotor"), out);
  return out;
}

std::string joined_names(const std::vector<LibraryEffect>& library) {
  std::string out;
  for (const auto& e : library) out += (out.empty() ? "" : ", ") + e.name;
  return out;
}

}  // namespace

const std::vector<LibraryEffect>& effect_library(std::string_view system) {
  static const std::vector<LibraryEffect> kCartpole = cartpole_library();
  static const std::vector<LibraryEffect> kQuadrotor = quadrotor_library();
  if (system == "cartpole") return kCartpole;
  if (system == "quadrotor") return kQuadrotor;
  make_system(system);  // throws listing the known systems
  throw std::invalid_argument("no effect library for system '" + std::string(system) + "'");
}

std::string effect_names(std::string_view system) { return joined_names(effect_library(system)); }

const LibraryEffect& find_effect(std::string_view system, std::string_view name) {
  const auto& library = effect_library(system);
  for (const auto& e : library)
    if (e.name == name) return e;
  throw std::invalid_argument(fmt::format("unknown effect '{}' for system '{}'; expected one of: {}", name, system,
                                          joined_names(library)));
}

DynamicsPtr ModelSpec::build(const ActuatorNoise& noise) const {
  DynamicsPtr base = make_system(system, preset, parameters);
  if (actuator_gain == 1.0 && forces.empty()) {
    if (noise.column_count() == 0) return base;
    return make_system(system, preset, parameters, noise);
  }
  std::vector<AppliedEffect> applied;
  for (const auto& [name, values] : forces) {
    const LibraryEffect& e = find_effect(system, name);
    if (e.kind != EffectKind::Force)
      throw std::invalid_argument("effect '" + name + "' is not a force; set it through the gain or the parameters");
    applied.push_back({e.force, values});
  }
  auto model = std::make_shared<EffectDynamics>(std::move(base), actuator_gain, std::move(applied));
  model->set_noise_model(noise);
  return model;
}

Vector ModelSpec::current_values(const LibraryEffect& effect) const {
  switch (effect.kind) {
    case EffectKind::Force:
      for (const auto& [name, values] : forces)
        if (name == effect.name) return values;
      return Vector::Zero(static_cast<Eigen::Index>(effect.parameters.size()));
    case EffectKind::ActuatorGain:
      return Vector::Constant(1, actuator_gain);
    case EffectKind::Recalibration:
      for (const Parameter& p : make_system(system, preset, parameters)->parameters())
        if (p.name == effect.recalibrated) return Vector::Constant(1, p.value);
      break;
  }
  throw std::invalid_argument("effect '" + effect.name + "' does not apply to system '" + system + "'");
}

ModelSpec ModelSpec::with(const LibraryEffect& effect, const VectorCRef& values) const {
  const auto expected = static_cast<Eigen::Index>(effect.parameters.size());
  if (values.size() != expected)
    throw std::invalid_argument(fmt::format("effect '{}' takes {} value(s); got {}", effect.name, expected, values.size()));
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const EffectParameter& p = effect.parameters[static_cast<std::size_t>(i)];
    if (!std::isfinite(values(i)) || values(i) < p.lower || values(i) > p.upper)
      throw std::invalid_argument(fmt::format("effect '{}': {} = {}; expected a finite value in [{}, {}] {}", effect.name,
                                              p.name, values(i), p.lower, p.upper, p.unit));
  }
  ModelSpec out = *this;
  switch (effect.kind) {
    case EffectKind::Force: {
      bool replaced = false;
      for (auto& [name, v] : out.forces)
        if (name == effect.name) {
          v = values;
          replaced = true;
        }
      if (!replaced) out.forces.emplace_back(effect.name, values);
      break;
    }
    case EffectKind::ActuatorGain:
      out.actuator_gain = values(0);
      break;
    case EffectKind::Recalibration:
      out.parameters[effect.recalibrated] = values(0);
      break;
  }
  return out;
}

std::vector<std::string> ModelSpec::describe() const {
  std::vector<std::string> lines;
  for (const auto& [name, value] : parameters) {
    const LibraryEffect& e = find_effect(system, "param:" + name);
    lines.push_back(fmt::format("param:{}: {} = {:.6g} {}", name, name, value, e.parameters[0].unit));
  }
  if (actuator_gain != 1.0) lines.push_back(fmt::format("actuator_gain: k = {:.6g}", actuator_gain));
  for (const auto& [name, values] : forces) {
    const LibraryEffect& e = find_effect(system, name);
    std::string text = name + ":";
    for (std::size_t i = 0; i < e.parameters.size(); ++i)
      text += fmt::format(" {} = {:.6g} {}", e.parameters[i].name, values(static_cast<Eigen::Index>(i)), e.parameters[i].unit);
    lines.push_back(text);
  }
  return lines;
}

}  // namespace gpilqg
