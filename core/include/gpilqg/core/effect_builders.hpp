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

/// The smoothing velocity v0 of Coulomb friction, tanh(qdot / v0), when nothing chose another
/// [m/s or rad/s]: a model file or `--effect` without `v0`. The diagnosis chooses v0 from the data of
/// the coordinate instead (diagnosis/velocity_scales.hpp).
inline constexpr double kDefaultCoulombWidth = 0.05;

/// Each basis adds theta g(x) to Q and theta dg/dx to dQ/dx (LinearForceEffect::Basis).
/// g = -x(velocity) on `component`: viscous friction or damping.
LinearForceEffect::Basis viscous(int component, int velocity);
/// g = -tanh(x(velocity) / width) on `component`: Coulomb friction, smoothed over `width` (> 0).
LinearForceEffect::Basis coulomb(int component, int velocity, double width = kDefaultCoulombWidth);
/// g = -(x(position) - reference)^3 on `component`: a cubic (stiffening, or softening when theta < 0)
/// spring about the rest position `reference`, the Duffing term of m q'' + d q' + a q + b q^3 = u.
LinearForceEffect::Basis cubic_spring(int component, int position, double reference);
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

/// Coulomb friction on one coordinate, Q_<coordinate> = -<parameter> tanh(<velocity> / v0), with its
/// smoothing (LibraryEffect::smoothing) so that the same entry can be made at another v0
/// (with_smoothing). `coordinate` and `velocity` are the names in the formula ("x", "x_dot");
/// `component` the force component, `velocity_index` the state index of the velocity.
LibraryEffect coulomb_friction_entry(std::string name, EffectParameter parameter, const std::string& coordinate,
                                     const std::string& velocity, int force_dim, int component, int velocity_index,
                                     double width = effect_bases::kDefaultCoulombWidth);

/// A constant generalised force on one coordinate, "constant_force:<coordinate>": Q_<coordinate> = F,
/// an offset or bias (gravity-compensation error, cable and hose forces, a sensor's offset).
LibraryEffect constant_force_entry(const std::string& coordinate, const std::string& force, const std::string& unit,
                                   int force_dim, int component);

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
