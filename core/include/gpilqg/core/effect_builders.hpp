#pragma once
/// @file effect_builders.hpp
/// The building blocks of effect libraries, shared by the built-in systems, MuJoCo models and
/// plugins: force bases linear in one parameter (Q = theta g(x)), library entries for forces, the
/// actuator gain and parameter recalibrations.

#include <string>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/effects.hpp"

namespace gpilqg::effect_bases {

/// Width of the tanh that smooths Coulomb friction (DESIGN.md sections 5 and 10) [m/s or rad/s].
inline constexpr double kCoulombWidth = 0.05;

/// Each basis adds theta g(x) to Q and theta dg/dx to dQ/dx (LinearForceEffect::Basis).
/// g = -x(velocity) on `component`: viscous friction or damping.
LinearForceEffect::Basis viscous(int component, int velocity);
/// g = -tanh(x(velocity) / 0.05) on `component`: Coulomb friction, smoothed.
LinearForceEffect::Basis coulomb(int component, int velocity);
/// g = e_component: a constant generalised force.
LinearForceEffect::Basis constant(int component);
/// g_i = -|v_i| v_i for `components` velocities starting at x(first_velocity): quadratic drag.
LinearForceEffect::Basis quadratic_drag(int components, int first_velocity);

}  // namespace gpilqg::effect_bases

namespace gpilqg {

/// A library entry of kind Force for a linear force effect with one parameter.
LibraryEffect linear_force_entry(std::string name, EffectParameter parameter, std::string formula, int force_dim,
                                 LinearForceEffect::Basis basis);

/// A library entry of kind Force for any force effect.
LibraryEffect force_entry(ForceEffectPtr force);

/// "actuator_gain" (k, the applied input is k u, on every control).
LibraryEffect actuator_gain_entry();

/// "input_delay" (d in control periods, 0 to kMaxInputDelay: the applied input is u(t - d); input_delay.hpp).
LibraryEffect input_delay_entry();

/// A recalibration entry: `effect_name` (e.g. "param:pole_length") sets the system parameter
/// `parameter` (e.g. "pole_length") to the fitted value. `non_negative` lets the value reach 0;
/// otherwise it stays above 1e-6 times the current value (masses, lengths). `linear` says xdot is
/// linear in the parameter.
LibraryEffect recalibration_entry(std::string effect_name, const Parameter& parameter, bool non_negative, bool linear);

}  // namespace gpilqg
