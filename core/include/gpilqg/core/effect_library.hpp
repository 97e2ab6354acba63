#pragma once
/// @file effect_library.hpp
/// The physical-effects library
/// (docs/diagnosis.md#the-physical-effects-library-coreeffect_libraryhpp-coreeffectshpp, fixed names)
/// and the model description the diagnosis works on: a system preset, recalibrated parameters, an
/// actuator gain and force effects.
///
/// | name                     | parameter      | enters as                                           |
/// |--------------------------|----------------|-----------------------------------------------------|
/// | cart_viscous_friction    | b [N s/m]      | Q_x = -b x_dot                                      |
/// | cart_coulomb_friction    | mu [N]         | Q_x = -mu tanh(x_dot / v0)                          |
/// | pole_viscous_damping     | c [N m s/rad]  | Q_theta = -c theta_dot                              |
/// | pole_coulomb_friction    | tau [N m]      | Q_theta = -tau tanh(theta_dot / v0)                 |
/// | actuator_gain            | k [-]          | the applied input is k u                            |
/// | external_force_x, _y, _z | F [N]          | constant force on the body (cart: x only)           |
/// | quadratic_drag           | c_d [N s^2/m^2]| -c_d abs(v) v on the translational velocity         |
/// | param:<name>             | the value      | recalibrates one physical parameter                 |
/// | input_delay              | d [steps]      | the applied input is u(t - d) (input_delay.hpp)     |
/// | constant_force:<coord>   | F [N or N m]   | Q_<coord> = F, an offset on every coordinate        |
///
/// Coulomb friction is smoothed over a velocity v0 (LibraryEffect::smoothing): a sign function has no
/// derivative at 0, and measured velocities near 0 are noise. v0 is a property of the model
/// (ModelSpec::smoothing): 0.05 (kDefaultCoulombWidth) unless the model says otherwise; the diagnosis
/// chooses it from the data of each coordinate. `constant_force:<coord>` is added to every system with
/// a generalised-force map, for each of its coordinates (complete_system_entry).
///
/// `quadratic_drag` is elementwise, F_i = -c_d |v_i| v_i (the cart: Q_x = -c_d |x_dot| x_dot; the
/// quadrotor: per world axis, drag of a body with the same area in every direction along the axes).
/// The cart-pole friction and damping effects apply to the cart-pole only; the quadrotor's external
/// forces act at the centre of mass in the world frame. `param:<name>` exists for every physical
/// parameter of the system except gravity.
///
/// Beside the library, a model carries the effects its user declared (ModelSpec::user_effects, the
/// model file's [[user_effects]]): basis forces on one coordinate (basis_force.hpp). The diagnosis fits,
/// ranks and adds the model's candidates, candidate_effects(model): the library, then those.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gpilqg/core/basis_force.hpp"
#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/systems.hpp"

namespace gpilqg {

enum class EffectKind {
  Force,          ///< a generalised force (ForceEffect)
  ActuatorGain,   ///< the applied input is k u
  Recalibration,  ///< one physical parameter takes another value
  InputDelay,     ///< the applied input is the command of d control periods earlier (input_delay.hpp)
};

/// One candidate of the library for one system.
struct LibraryEffect {
  std::string name;                        ///< the fixed name, e.g. "cart_coulomb_friction", "param:pole_length"
  EffectKind kind = EffectKind::Force;
  std::vector<EffectParameter> parameters;  ///< one entry for every built-in effect
  std::string formula;                     ///< e.g. "Q_x = -mu tanh(x_dot / 0.05)"
  bool linear = false;                     ///< xdot is linear in the parameters
  ForceEffectPtr force;                    ///< kind == Force only
  std::string recalibrated;                ///< kind == Recalibration: the parameter's name, e.g. "pole_length"
                                           ///< (for MuJoCo's actuator_gain:<a>, the parameter "<a>.gain")
  /// Coulomb friction, -tau tanh(qdot / v0): its smoothing velocity and the same force at another v0.
  struct Smoothing {
    int velocity = -1;   ///< state index of qdot
    double width = 0.0;  ///< v0 [m/s or rad/s], > 0
    std::function<ForceEffectPtr(double v0)> at;
  };
  std::optional<Smoothing> smoothing;      ///< Coulomb friction only (coulomb_friction_entry)
  /// A candidate the diagnosis ranks and searches only when asked to (`--include`, or named by
  /// `--add`): a freedom that, offered by default, the search spends on fitting what other effects
  /// are (a body's second moments of mass).
  bool on_request = false;
};

/// `effect` (which has a smoothing) at the smoothing velocity `v0`: its force and formula rebuilt.
/// Throws std::invalid_argument when the effect has no smoothing or v0 is not finite and > 0.
LibraryEffect with_smoothing(const LibraryEffect& effect, double v0);

/// Every effect of the library that applies to `system` (a registered name or a MuJoCo model file,
/// system_registry.hpp), in the entry's fixed order; for the built-in systems: forces, actuator_gain,
/// then param:<name> in the system's parameter order. Throws std::invalid_argument listing the systems
/// for an unknown name.
const std::vector<LibraryEffect>& effect_library(std::string_view system);

/// The library entry called `name`. Throws std::invalid_argument naming `name` and listing every
/// valid name for the system.
const LibraryEffect& find_effect(std::string_view system, std::string_view name);

/// The names of effect_library(system), comma-separated, for error messages.
std::string effect_names(std::string_view system);

/// The library entry (kind Force, linear) of a force the user declares for `system` (a BasisForceEffect).
/// Throws DeclarationError (basis_force.hpp) for an invalid declaration, and with field "name" when
/// the name is one of the library's (naming it and its formula), or the system has no generalised-force map.
LibraryEffect user_effect_entry(std::string_view system, const BasisForceDeclaration& declaration);

/// The declaration of a user-declared effect, or null for any other effect.
const BasisForceDeclaration* user_declaration(const LibraryEffect& effect);

/// A model to compare with measurements: the preset's system with recalibrated parameters, an
/// actuator gain, force effects of the library or declared by the user with their parameter values,
/// and the user-declared effects the diagnosis may add.
struct ModelSpec {
  std::string system = "cartpole";
  Preset preset = Preset::Simulator;
  std::map<std::string, double> parameters;        ///< recalibrations: name -> value (overrides the preset)
  double actuator_gain = 1.0;                      ///< k
  std::vector<std::pair<std::string, Vector>> forces;  ///< force effects (library or user) -> parameter values, in order
  /// Effects the user declared (user_effect_entry), in declaration order, whether or not `forces` uses
  /// them: candidates of the diagnosis beside the library. Names differ from the library's and each other's.
  std::vector<LibraryEffect> user_effects;
  /// d [control periods]: the applied input is u(t - d). Not part of the Dynamics (which maps the
  /// applied input to xdot): whoever drives the model with measured or commanded inputs applies it
  /// (delay_controls, input_delay.hpp): the diagnosis's predictions, the simulated world.
  double input_delay = 0.0;
  /// Smoothing velocities v0 of Coulomb effects (LibraryEffect::smoothing) by effect name, where they
  /// differ from the entry's default; candidate_effects and find_candidate return the entries at these.
  std::map<std::string, double> smoothing;

  /// The model's Dynamics (an EffectDynamics when it has a gain other than 1 or forces), with `noise`;
  /// without the input delay (see input_delay).
  /// Throws std::invalid_argument for an unknown system, parameter or effect, or invalid values.
  DynamicsPtr build(const ActuatorNoise& noise = {}) const;

  /// The values the model gives `effect`'s parameters now: a force's values (0 when absent), the
  /// gain, or the (possibly recalibrated) physical parameter. Adding the effect at these values
  /// leaves the model unchanged.
  Vector current_values(const LibraryEffect& effect) const;

  /// This model with `effect` at `values` (a force replaces its previous values, the gain and a
  /// parameter are set). A force that is not in the system's library is a user effect: it is added to
  /// user_effects (or replaces the one of its name). Throws std::invalid_argument for a wrong number of
  /// values, a non-finite value or one outside the parameter's physical bounds.
  ModelSpec with(const LibraryEffect& effect, const VectorCRef& values) const;

  /// One line per difference from the preset, e.g. "cart_coulomb_friction: mu = 1.98 N"; empty for
  /// the bare preset.
  std::vector<std::string> describe() const;
};

/// The candidates the diagnosis fits for `model` (ranking, --add, forward selection): the system's
/// library (effect_library), then the model's user effects in declaration order; Coulomb effects at
/// the model's smoothing velocities (ModelSpec::smoothing).
std::vector<LibraryEffect> candidate_effects(const ModelSpec& model);

/// The candidate of `model` called `name` (a copy: it stays valid when the model changes). Throws
/// std::invalid_argument naming `name` and the system and listing every candidate's name.
LibraryEffect find_candidate(const ModelSpec& model, std::string_view name);

/// `model` with its physical parameter `name` set to `value` (a `--param`, a config's [world]
/// parameters): through the parameter's recalibration effect ("param:<name>") when the system's
/// library has one, which checks the value against its range (EffectParameter::lowest/highest); else
/// as given (the system checks the name when it is built). Throws std::invalid_argument for a value
/// outside the range.
ModelSpec with_parameter(const ModelSpec& model, const std::string& name, double value);

/// The names of candidate_effects(model), comma-separated, for error messages.
std::string candidate_names(const ModelSpec& model);

}  // namespace gpilqg
