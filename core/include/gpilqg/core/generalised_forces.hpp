#pragma once
/// @file generalised_forces.hpp
/// Mechanical systems that accept extra generalised forces in their equations of motion,
///
///   M(q) q_ddot = h(q, q_dot, u) + Q,
///
/// which in first-order form adds W(x) Q to the state derivative: xdot = f(x, u) + W(x) Q, with
/// W = [0; M^-1] laid out on the velocity rows. This is how the physical-effects library
/// (effects.hpp) adds friction, drag and external forces to a system without knowing its equations.
///
/// Each force component Q_k acts on one generalised coordinate q_k, with position x(position) and
/// velocity x(velocity) in the state (GeneralisedCoordinate). User-declared effects (basis_force.hpp)
/// name a coordinate and are functions of (q_k, q_dot_k, u).

#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

/// The generalised coordinate that one force component acts on.
struct GeneralisedCoordinate {
  std::string name;   ///< e.g. "x", "theta", a MuJoCo joint's name, the quadrotor's "px" or "rx"
  std::string force;  ///< the force component's name, e.g. "Q_x", "F_x", "tau_x"
  int component = 0;  ///< index of the component in generalised_forces()
  int position = 0;   ///< state index of q
  int velocity = 0;   ///< state index of q_dot
};

class GeneralisedForceInput {
 public:
  virtual ~GeneralisedForceInput() = default;

  /// The k generalised-force components in their fixed order, with units (e.g. Q_x [N], Q_theta [N m]).
  virtual const std::vector<Quantity>& generalised_forces() const = 0;

  /// W(x) (n x k, resized if needed) such that xdot gains W(x) Q. When `d_dx` is not null it receives
  /// n matrices (n x k each): entry j is dW/dx_j.
  virtual void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const = 0;
  /// The same with the workspace of the system (Dynamics::make_workspace()); the default calls the
  /// form without one.
  virtual void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx,
                                     DynamicsWorkspace&) const {
    generalised_force_map(x, W, d_dx);
  }

  /// Its inverse dynamics, for systems that compute it directly: the generalised force
  ///
  ///   Q = W_v(x)^-1 (qdd - f_v(x, u)) = M(q) qdd - h(q, q_dot, u)
  ///
  /// (k entries) that gives the accelerations `qdd` (one per component, in component order) at
  /// (x, u), where f_v and W_v are the velocity rows of the state derivative and of
  /// generalised_force_map, in its two terms, Q = inertial + forces: inertial = M(q) qdd, the term
  /// linear in the accelerations, and forces = -h(q, q_dot, u) = -W_v^-1 f_v(x, u), the generalised
  /// force at zero acceleration (what parallel filtering sees through the acceleration estimate's
  /// weights). Returns false, with both unspecified, where the system has no direct form at (x, u) and
  /// the caller must solve W_v Q = qdd - f_v itself; the default always does.
  virtual bool inverse_dynamics_parts(const VectorCRef& /*x*/, const VectorCRef& /*u*/, const VectorCRef& /*qdd*/,
                                      VectorRef /*inertial*/, VectorRef /*forces*/, DynamicsWorkspace&) const {
    return false;
  }

  /// The generalised force the controls apply at (x, u), Q_u = B(x) u for actuators linear in their
  /// input (k entries): the actuation alone, without the reaction of constraints that the forward
  /// dynamics hold (a MuJoCo frictionloss that sticks near a reversal absorbs part of a torque, so
  /// there the forward Jacobian's W_v^-1 df_v/du is not B). Returns false, with Q unspecified, where
  /// the system does not compute it; the default always does.
  virtual bool control_forces(const VectorCRef& /*x*/, const VectorCRef& /*u*/, VectorRef /*Q*/,
                              DynamicsWorkspace&) const {
    return false;
  }

  /// The coordinates the force components act on, for systems whose components do not follow the
  /// naming convention of generalised_coordinates() (the quadrotor: F_x acts on px and vx, tau_x on
  /// rx and wx). Empty by default: the convention applies.
  virtual std::vector<GeneralisedCoordinate> coordinates() const { return {}; }
};

/// The generalised coordinates of `system`, in the order of its force components: its own
/// GeneralisedForceInput::coordinates() when not empty, else by the naming convention the built-in
/// cart-pole, MuJoCo models and the example plugin share: the component "Q_<c>" acts on the
/// coordinate "<c>" with the states "<c>" (q) and "<c>_dot" (q_dot). Components without such states
/// have no coordinate and are left out. Empty when the system has no generalised-force map.
std::vector<GeneralisedCoordinate> generalised_coordinates(const Dynamics& system);

/// The coordinate of `system` called `name` (its coordinate name, e.g. "x", or its force component's,
/// e.g. "Q_x"). Throws std::invalid_argument naming `name` and listing the valid names (or saying that
/// the system has no generalised-force map).
GeneralisedCoordinate find_coordinate(const Dynamics& system, std::string_view name);

}  // namespace gpilqg
