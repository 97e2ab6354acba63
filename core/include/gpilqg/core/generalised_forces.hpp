#pragma once
/// @file generalised_forces.hpp
/// Mechanical systems that accept extra generalised forces in their equations of motion,
///
///   M(q) q_ddot = h(q, q_dot, u) + Q,
///
/// which in first-order form adds W(x) Q to the state derivative: xdot = f(x, u) + W(x) Q, with
/// W = [0; M^-1] laid out on the velocity rows. This is how the physical-effects library
/// (effects.hpp) adds friction, drag and external forces to a system without knowing its equations.

#include <vector>

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/quantity.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

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
};

}  // namespace gpilqg
