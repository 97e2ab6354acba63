#pragma once
/// @file effects.hpp
/// Physical effects
/// (docs/diagnosis.md#the-physical-effects-library-coreeffect_libraryhpp-coreeffectshpp): named,
/// parameterised generalised forces added to a mechanical system's equations of motion, and the
/// Dynamics decorator "system + effects".
///
/// With the system's generalised-force map W(x) (generalised_forces.hpp), an actuator gain k and
/// effects e = 1..E with parameters theta_e,
///
///   M(q) q_ddot = h(q, q_dot, k u) + sum_e Q_e(x, u; theta_e)
///   xdot        = f(x, k u) + W(x) Q(x, u),           Q = sum_e Q_e  (k_Q entries)
///
/// and the Jacobians, exact by the chain rule (tests/core/effects_test.cpp checks them against central
/// differences):
///
///   f_x = f_x^base(x, k u) + W dQ/dx + [ (dW/dx_1) Q, ..., (dW/dx_n) Q ]
///   f_u = k f_u^base(x, k u) + W dQ/du
///
/// Parameter recalibrations ("param:<name>") are not forces: they rebuild the base system with another
/// parameter value (effect_library.hpp, ModelSpec).

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/generalised_forces.hpp"

namespace gpilqg {

/// One parameter of an effect, e.g. {"b", "N s/m", 1.0}.
struct EffectParameter {
  std::string name;
  std::string unit;
  /// Typical magnitude: sets the finite-difference step and the search box when the parameter is fitted.
  double scale = 1.0;
  /// Physical bounds (a mass stays positive); infinite when the sign is free.
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  /// A quantity that cannot be zero (a mass, a length; `lower` is then above 0): its own value is the
  /// yardstick of what the data can weigh (effect_test.hpp, test 1).
  bool strictly_positive = false;

  /// How far a value may lie from the typical magnitude, as a ratio: a model with a pole a million
  /// times its own length, or a gain of 1e308, is no physical model, and its failure would surface
  /// far from its cause (a solver's bound, an overflow, a "converged" solve on a 1e300 kg forearm).
  static constexpr double kMaxScaleRatio = 1e6;
  /// The values the parameter may take: [lower, upper] within kMaxScaleRatio * scale of 0 either way
  /// (for a recalibration, scale is the model's own value). Every model file, option and fit checks
  /// against these (ModelSpec::with), and a fit's steps stay inside them.
  double lowest() const { return scale > 0.0 && std::isfinite(scale) ? std::max(lower, -kMaxScaleRatio * scale) : lower; }
  double highest() const { return scale > 0.0 && std::isfinite(scale) ? std::min(upper, kMaxScaleRatio * scale) : upper; }
};

/// A generalised force Q(x, u; theta) with k_Q entries, in the components of the system's
/// GeneralisedForceInput. Immutable and shareable between threads.
class ForceEffect {
 public:
  virtual ~ForceEffect() = default;
  /// The effect's name, e.g. "cart_viscous_friction".
  virtual const std::string& name() const = 0;
  virtual const std::vector<EffectParameter>& parameters() const = 0;
  /// How it enters, e.g. "Q_x = -b x_dot".
  virtual const std::string& formula() const = 0;
  /// True when Q depends on u (then dQ/du may be nonzero).
  virtual bool depends_on_input() const { return false; }
  /// True when Q is linear in theta (least squares then estimates theta directly).
  virtual bool linear_in_parameters() const { return false; }
  /// Adds Q(x, u; theta) to `Q` (k_Q entries) and, when not null, dQ/dx to `dQ_dx` (k_Q x n) and
  /// dQ/du to `dQ_du` (k_Q x m). `u` is the commanded input. `theta` has parameters().size() entries.
  virtual void add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q,
                         Matrix* dQ_dx, Matrix* dQ_du) const = 0;
  /// The same with the workspace of the system the force acts on (for effects that evaluate the
  /// system, such as a force at a MuJoCo body's centre of mass); the default calls the form without.
  virtual void add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q,
                         Matrix* dQ_dx, Matrix* dQ_du, DynamicsWorkspace&) const {
    add_force(x, u, theta, Q, dQ_dx, dQ_du);
  }
};

using ForceEffectPtr = std::shared_ptr<const ForceEffect>;

/// Q = theta g(x): a force linear in its one parameter, with a basis g(x) (k_Q entries) that does not
/// depend on u. Every force of the built-in library has this form.
class LinearForceEffect final : public ForceEffect {
 public:
  /// Adds theta g(x) to `Q` (k_Q entries) and, when not null, theta dg/dx to `dQ_dx` (k_Q x n).
  using Basis = std::function<void(const VectorCRef& x, double theta, VectorRef Q, Matrix* dQ_dx)>;

  /// `force_dim` is k_Q of the systems this effect applies to. Throws std::invalid_argument for an
  /// empty name, a null basis or force_dim < 1.
  LinearForceEffect(std::string name, EffectParameter parameter, std::string formula, int force_dim, Basis basis);

  const std::string& name() const override { return name_; }
  const std::vector<EffectParameter>& parameters() const override { return parameters_; }
  const std::string& formula() const override { return formula_; }
  bool linear_in_parameters() const override { return true; }
  void add_force(const VectorCRef& x, const VectorCRef& u, const VectorCRef& theta, VectorRef Q, Matrix* dQ_dx,
                 Matrix* dQ_du) const override;

 private:
  std::string name_;
  std::vector<EffectParameter> parameters_;
  std::string formula_;
  int force_dim_;
  Basis basis_;
};

/// An effect with its parameter values.
struct AppliedEffect {
  ForceEffectPtr effect;
  Vector theta;
};

/// "System + effects": the base system driven by k u, plus the generalised forces of the effects.
/// Name, states and controls are the base system's, so its data files are the base system's.
/// The noise model is the decorator's own (set_noise_model), with b = df/du of the decorated system.
class EffectDynamics final : public Dynamics {
 public:
  /// Throws std::invalid_argument for a null base, a non-finite gain, a null effect, a theta of the
  /// wrong size or with non-finite entries, or effects on a base that is not a GeneralisedForceInput.
  EffectDynamics(DynamicsPtr base, double actuator_gain, std::vector<AppliedEffect> effects);

  const std::string& name() const override { return base_->name(); }
  const std::vector<Quantity>& states() const override { return base_->states(); }
  const std::vector<Quantity>& controls() const override { return base_->controls(); }
  /// The base system's parameters, then "actuator_gain.k", then "<effect>.<parameter>" per effect.
  std::vector<Parameter> parameters() const override;

  /// Holds the base system's workspace and the forces' buffers.
  std::unique_ptr<DynamicsWorkspace> make_workspace() const override;
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jacobians = nullptr) const override;
  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot, DynamicsJacobians* jacobians,
                DynamicsWorkspace& workspace) const override;
  /// Analytic when no effect depends on u: b = k b^base(x, k u) + W dQ/du with dQ/du = 0, so
  /// db_j/dx = k db_j^base/dx and db_j/du = k^2 db_j^base/du_a; otherwise central differences.
  void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const override;
  void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out,
                    DynamicsWorkspace& workspace) const override;

  /// Q(x, u) = sum_e Q_e(x, u; theta_e) (k_Q entries, the base system's generalised forces); `u` is
  /// the commanded input. Used by systems that integrate the forces themselves (OwnIntegrator).
  /// `workspace` is one of this system's (make_workspace()).
  void generalised_force(const VectorCRef& x, const VectorCRef& u, VectorRef Q, DynamicsWorkspace& workspace) const;

  const Dynamics& base() const { return *base_; }
  double actuator_gain() const { return gain_; }
  /// Whether an effect's force depends on the controls (then the input matrix is not k times the base's).
  bool input_dependent() const { return input_dependent_; }
  const std::vector<AppliedEffect>& effects() const { return effects_; }

 private:
  DynamicsPtr base_;
  const GeneralisedForceInput* forces_ = nullptr;  ///< base_ viewed as a GeneralisedForceInput (or null)
  double gain_;
  std::vector<AppliedEffect> effects_;
  bool input_dependent_ = false;
};

}  // namespace gpilqg
