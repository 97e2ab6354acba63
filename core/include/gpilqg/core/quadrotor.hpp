#pragma once
/// @file quadrotor.hpp
/// Quadrotor after van den Berg ("Extended LQR"), as written in the paper with the factor that
/// docs/formats.md#systems-and-their-names restores. State [p (3), v (3), r (3), w (3)]: position and
/// velocity in the world frame, r a rotation vector (rotation about r/|r| by |r|), w the body angular
/// velocity. Controls: the four rotor forces u1..u4 [N].
///
///   p_dot = v
///   v_dot = -g e3 + ((u1 + u2 + u3 + u4) R(r) e3 - kv v) / m,       R(r) = exp([r])  (Rodrigues)
///   r_dot = w + 1/2 [r] w + (1 - (|r|/2) / tan(|r|/2)) [r]^2 w / |r|^2
///   w_dot = J^-1 (rho (u2 - u4) e1 + rho (u3 - u1) e2 + km (u1 - u2 + u3 - u4) e3 - [w] J w)
///
/// [a] is the cross-product matrix. The coefficient c(t) = (1 - (t/2) cot(t/2)) / t^2 of [r]^2 w has a
/// removable singularity at t = |r| = 0 (c -> 1/12); it and its derivative are evaluated by their Taylor
/// series for small |r|, so f and its exact Jacobians are smooth through r = 0.
///
/// Conventions worth knowing:
/// - r_dot = J_r(r)^-1 w, the inverse right Jacobian of SO(3): it is the rotation-vector rate of
///   R_dot = R [w], so w is the angular velocity in the body frame (as in the Euler equation for
///   w_dot). The rotation-vector kinematics are singular at |r| = 2 pi (c has a pole there); the model
///   is meant for |r| < 2 pi.
/// - With J = inertia I the gyroscopic term [w] J w = inertia (w x w) vanishes identically, so w_dot
///   depends on u only.
/// - Rotor layout implied by the torques: rotors 1 and 3 on the body x axis at +rho and -rho, 2 and 4
///   on the y axis at +rho and -rho; 1 and 3 produce yaw torque +km u, 2 and 4 -km u.
/// - evaluate() and input_matrix() compute exact analytic derivatives and do not allocate once the
///   caller's buffers have their size. Below |r| = 1 rad the rotation coefficients come from their
///   series (no trigonometric calls); above, from their closed forms (see quadrotor.cpp).

#include "gpilqg/core/dynamics.hpp"
#include "gpilqg/core/generalised_forces.hpp"

namespace gpilqg {

struct QuadrotorParameters {
  double mass = 0.5;      ///< m [kg]
  double kv = 0.15;       ///< velocity drag coefficient kv [N s/m]
  double km = 0.025;      ///< rotor torque constant km [m]: yaw torque per unit rotor force
  double inertia = 0.05;  ///< J = inertia * I_3 [kg m^2]
  double rho = 0.17;      ///< distance from the centre of mass to each rotor [m]
  double gravity = 9.81;  ///< g [m/s^2]

  /// The paper's simulator: m = 0.5 kg, kv 0.15, km 0.025, J = 0.05 I, rho 0.17.
  static QuadrotorParameters simulator() { return {}; }
  /// The paper's real world: 40% heavier, m = 0.7 kg.
  static QuadrotorParameters real_world() { return {0.7, 0.15, 0.025, 0.05, 0.17, 9.81}; }
};

class Quadrotor final : public Dynamics, public GeneralisedForceInput {
 public:
  /// Throws std::invalid_argument naming the parameter and its value when mass, inertia, rho or
  /// gravity is not a finite value > 0, or kv or km is not a finite value >= 0.
  explicit Quadrotor(QuadrotorParameters parameters = QuadrotorParameters::simulator());

  const std::string& name() const override;
  const std::vector<Quantity>& states() const override;
  const std::vector<Quantity>& controls() const override;
  std::vector<Parameter> parameters() const override;
  const QuadrotorParameters& physical() const { return p_; }

  void evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                DynamicsJacobians* jacobians = nullptr) const override;
  void input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const override;

  /// The rotor force that holds the quadrotor in hover, m g / 4 [N] per rotor.
  double hover_force() const { return p_.mass * p_.gravity / 4.0; }

  /// Generalised forces Q = (F_x, F_y, F_z [N], a force on the centre of mass in the world frame;
  /// tau_x, tau_y, tau_z [N m], a torque in the body frame): v_dot gains F / m and w_dot gains
  /// tau / inertia, so W = [0; I/m; 0; I/inertia] (12 x 6) is constant and every dW/dx_j is zero.
  const std::vector<Quantity>& generalised_forces() const override;
  void generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const override;
  /// F_x, F_y, F_z act on the coordinates px, py, pz (q = p_i, q_dot = v_i); tau_x, tau_y, tau_z on
  /// rx, ry, rz (q = r_i, the rotation vector's component, q_dot = w_i, the body rate: r_dot = w only
  /// near r = 0).
  std::vector<GeneralisedCoordinate> coordinates() const override;

 private:
  QuadrotorParameters p_;
};

}  // namespace gpilqg
