#pragma once
/// @file cartpole.hpp
/// Cart-pole with a point mass at the tip of a massless pole (Tedrake, Underactuated Robotics, ch. 3),
/// the paper's first system. States [x, x_dot, theta, theta_dot], theta = 0 hanging down, theta = pi
/// upright; control: the horizontal force on the cart [N].
///
/// Equations of motion in manipulator form, q = (x, theta), s = sin(theta), c = cos(theta):
///
///   M(q) q_ddot = h(q, q_dot, u)
///   M = [ mc + mp      mp l c ]      h = [ u + mp l s theta_dot^2 ]
///       [ mp l c       mp l^2 ]          [ -mp g l s             ]
///
/// whose solution is the form in tests/reference/ilqr_cartpole/README.md:
///   x_ddot     = (u + mp s (l theta_dot^2 + g c)) / (mc + mp s^2)
///   theta_ddot = (-u c - mp l theta_dot^2 c s - (mc + mp) g s) / (l (mc + mp s^2))
/// Jacobians: d q_ddot / d z = M^-1 (dh/dz - dM/dz q_ddot) for z in (q, q_dot, u).

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/generalised_forces.hpp"

namespace gpilqg {

struct CartPoleParameters {
  double cart_mass = 1.0;    ///< mc [kg]
  double pole_mass = 1.0;    ///< mp [kg], a point mass at the tip
  double pole_length = 1.0;  ///< l [m]
  double gravity = 9.81;     ///< g [m/s^2]

  /// The paper's simulator: cart 1 kg, pole 1 kg, length 1 m.
  static CartPoleParameters simulator() { return {}; }
  /// The paper's real world: the pole is 30% longer (1.3 m).
  static CartPoleParameters real_world() { return {1.0, 1.0, 1.3, 9.81}; }
};

class CartPole final : public Dynamics, public GeneralisedForceInput {
 public:
  /// Throws std::invalid_argument naming the parameter when a mass or the length is not positive.
  explicit CartPole(CartPoleParameters parameters = CartPoleParameters::simulator());

  const std::string& name() const override;
  const std::vector<Quantity>& states() const override;
  const std::vector<Quantity>& controls() const override;
  std::vector<Parameter> parameters() const override;
  const CartPoleParameters& physical() const { return p_; }

  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jacobians = nullptr) const override;
  void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const override;

  /// Total mechanical energy (kinetic + potential, zero at the hanging rest state) [J]; conserved
  /// with no input and no friction.
  double energy(const VectorCRef& x) const;

  /// Generalised forces Q = (Q_x [N] along the rail, Q_theta [N m] about the pivot) added to h:
  /// q_ddot gains M^-1 Q, so W(x) has rows 1 and 3 equal to the rows of M^-1(theta) and zeros
  /// elsewhere; dW/dtheta = -M^-1 (dM/dtheta) M^-1 on the same rows, every other dW/dx_j is zero.
  const std::vector<Quantity>& generalised_forces() const override;
  void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const override;

 private:
  CartPoleParameters p_;
};

}  // namespace gpilqg
