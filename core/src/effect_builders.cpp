#include "gpilqg/core/effect_builders.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "gpilqg/core/input_delay.hpp"

namespace gpilqg::effect_bases {

LinearForceEffect::Basis viscous(int component, int velocity) {
  return [=](const VectorCRef& x, double theta, VectorRef Q, Matrix* dQ_dx) {
    Q(component) -= theta * x(velocity);
    if (dQ_dx != nullptr) (*dQ_dx)(component, velocity) -= theta;
  };
}

LinearForceEffect::Basis coulomb(int component, int velocity, double width) {
  if (!(width > 0.0) || !std::isfinite(width))
    throw std::invalid_argument("Coulomb friction: smoothing velocity v0 = " + std::to_string(width) +
                                "; expected a finite v0 > 0");
  // g = -tanh(v / w), dg/dv = -(1 - tanh^2) / w.
  return [=](const VectorCRef& x, double theta, VectorRef Q, Matrix* dQ_dx) {
    const double t = std::tanh(x(velocity) / width);
    Q(component) -= theta * t;
    if (dQ_dx != nullptr) (*dQ_dx)(component, velocity) -= theta * (1.0 - t * t) / width;
  };
}

LinearForceEffect::Basis cubic_spring(int component, int position, double reference) {
  // g = -e^3, dg/dq = -3 e^2, e = q - reference.
  return [=](const VectorCRef& x, double theta, VectorRef Q, Matrix* dQ_dx) {
    const double e = x(position) - reference;
    Q(component) -= theta * e * e * e;
    if (dQ_dx != nullptr) (*dQ_dx)(component, position) -= 3.0 * theta * e * e;
  };
}

LinearForceEffect::Basis constant(int component) {
  return [=](const VectorCRef&, double theta, VectorRef Q, Matrix*) { Q(component) += theta; };
}

LinearForceEffect::Basis quadratic_drag(int components, int first_velocity) {
  // g_i = -|v_i| v_i, dg_i/dv_i = -2 |v_i|.
  return [=](const VectorCRef& x, double theta, VectorRef Q, Matrix* dQ_dx) {
    for (int i = 0; i < components; ++i) {
      const double v = x(first_velocity + i);
      Q(i) -= theta * std::abs(v) * v;
      if (dQ_dx != nullptr) (*dQ_dx)(i, first_velocity + i) -= theta * 2.0 * std::abs(v);
    }
  };
}

}  // namespace gpilqg::effect_bases

namespace gpilqg {

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

LibraryEffect coulomb_friction_entry(std::string name, EffectParameter parameter, const std::string& coordinate,
                                     const std::string& velocity, int force_dim, int component, int velocity_index,
                                     double width) {
  LibraryEffect::Smoothing smoothing;
  smoothing.velocity = velocity_index;
  smoothing.width = width;
  smoothing.at = [=](double v0) {
    return std::make_shared<const LinearForceEffect>(
        name, parameter, fmt::format("Q_{} = -{} tanh({} / {:.4g})", coordinate, parameter.name, velocity, v0), force_dim,
        effect_bases::coulomb(component, velocity_index, v0));
  };
  LibraryEffect e = force_entry(smoothing.at(width));
  e.smoothing = std::move(smoothing);
  return e;
}

LibraryEffect constant_force_entry(const std::string& coordinate, const std::string& force, const std::string& unit,
                                   int force_dim, int component) {
  return linear_force_entry("constant_force:" + coordinate, {"F", unit, 1.0},
                            fmt::format("{} = F (a constant offset on {})", force, coordinate), force_dim,
                            effect_bases::constant(component));
}

LibraryEffect linear_force_entry(std::string name, EffectParameter parameter, std::string formula, int force_dim,
                                 LinearForceEffect::Basis basis) {
  return force_entry(std::make_shared<LinearForceEffect>(std::move(name), std::move(parameter), std::move(formula),
                                                         force_dim, std::move(basis)));
}

LibraryEffect actuator_gain_entry() {
  LibraryEffect e;
  e.name = "actuator_gain";
  e.kind = EffectKind::ActuatorGain;
  e.parameters = {{"k", "-", 1.0, 0.0, std::numeric_limits<double>::infinity()}};
  e.formula = "applied input = k u";
  e.linear = true;  // the built-in systems are control-affine
  return e;
}

LibraryEffect input_delay_entry() {
  LibraryEffect e;
  e.name = "input_delay";
  e.kind = EffectKind::InputDelay;
  e.parameters = {{"d", "steps", 1.0, 0.0, kMaxInputDelay}};
  e.formula = "applied input = u(t - d), fractional d by linear interpolation";
  e.linear = false;
  return e;
}

LibraryEffect recalibration_entry(std::string effect_name, const Parameter& parameter, bool non_negative, bool linear) {
  LibraryEffect e;
  e.name = std::move(effect_name);
  e.kind = EffectKind::Recalibration;
  e.recalibrated = parameter.name;
  const double magnitude = std::abs(parameter.value);
  e.parameters = {{parameter.name, parameter.unit, std::max(magnitude, 1e-3), non_negative ? 0.0 : 1e-6 * magnitude,
                   std::numeric_limits<double>::infinity(), !non_negative}};
  e.formula = "recalibrate " + parameter.name + " [" + parameter.unit + "]";
  e.linear = linear;
  return e;
}

}  // namespace gpilqg
