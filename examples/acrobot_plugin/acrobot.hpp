#pragma once
/// @file acrobot.hpp
/// The acrobot (Spong 1995; Tedrake, Underactuated Robotics, ch. 3): two links in a vertical plane,
/// a passive shoulder and a motor at the elbow only. States [theta1, theta2, theta1_dot, theta2_dot]:
/// theta1 is the first link's angle from hanging straight down, theta2 the elbow angle relative to
/// the first link; control tau [N m], the elbow torque. Both links are uniform rods: the centre of
/// mass at l_i / 2, inertia m_i l_i^2 / 3 about the link's own joint.
///
/// Manipulator form, q = (theta1, theta2), s_i = sin(theta_i), c_i = cos(theta_i),
/// s12 = sin(theta1 + theta2), a = m2 l1 lc2:
///
///   M(q) q_ddot = h(q, q_dot, tau)
///   M = [ I1 + I2 + m2 l1^2 + 2 a c2    I2 + a c2 ]
///       [ I2 + a c2                      I2        ]
///   h = [ -m1 g lc1 s1 - m2 g (l1 s1 + lc2 s12) + a s2 (2 theta1_dot theta2_dot + theta2_dot^2) ]
///       [ tau - m2 g lc2 s12 - a s2 theta1_dot^2                                                ]
///
/// (h = tau_g(q) + B tau - C(q, q_dot) q_dot with Spong's Coriolis matrix C and B = [0; 1]).
/// Jacobians: d q_ddot / d z = M^-1 (dh/dz - dM/dz q_ddot) for z in (q, q_dot, tau); M depends on
/// theta2 only, dM/dtheta2 = [-2 a s2, -a s2; -a s2, 0].
///
/// Generalised forces Q = (Q_theta1, Q_theta2) [N m] at the two joints enter as M q_ddot = h + Q, so
/// W(x) = [0; M^-1] and dW/dtheta2 = [0; -M^-1 (dM/dtheta2) M^-1]; every other dW/dx_j is zero.

#include <string>
#include <vector>

#include <gpilqg/core/dynamics.hpp>
#include <gpilqg/core/generalised_forces.hpp>

namespace acrobot {

struct AcrobotParameters {
  double link1_mass = 1.0;    ///< m1 [kg]
  double link2_mass = 1.0;    ///< m2 [kg]
  double link1_length = 1.0;  ///< l1 [m]
  double link2_length = 1.0;  ///< l2 [m]
  double gravity = 9.81;      ///< g [m/s^2]

  /// The simulator: two 1 kg, 1 m links.
  static AcrobotParameters simulator() { return {}; }
  /// The real world: the second link is 30% heavier (1.3 kg).
  static AcrobotParameters real_world() { return {1.0, 1.3, 1.0, 1.0, 9.81}; }
};

class Acrobot final : public gpilqg::Dynamics, public gpilqg::GeneralisedForceInput {
 public:
  /// Throws std::invalid_argument naming the parameter when a mass, a length or gravity is not a
  /// finite positive number.
  explicit Acrobot(AcrobotParameters parameters = AcrobotParameters::simulator());

  const std::string& name() const override;
  const std::vector<gpilqg::Quantity>& states() const override;
  const std::vector<gpilqg::Quantity>& controls() const override;
  /// link1_mass, link2_mass, link1_length, link2_length, gravity.
  std::vector<gpilqg::Parameter> parameters() const override;
  const AcrobotParameters& physical() const { return p_; }

  void evaluate(const gpilqg::VectorCRef& x, const gpilqg::VectorCRef& u, gpilqg::VectorRef xdot,
                gpilqg::DynamicsJacobians* jacobians = nullptr) const override;
  /// b = [0; M^-1 e2], db/dtheta2 = [0; -M^-1 (dM/dtheta2) M^-1 e2], db/du = 0.
  void input_matrix(const gpilqg::VectorCRef& x, const gpilqg::VectorCRef& u,
                    gpilqg::InputMatrix& out) const override;

  /// Kinetic plus potential energy, zero hanging at rest [J]; conserved with no torque and no friction.
  double energy(const gpilqg::VectorCRef& x) const;

  const std::vector<gpilqg::Quantity>& generalised_forces() const override;
  void generalised_force_map(const gpilqg::VectorCRef& x, gpilqg::Matrix& W,
                             std::vector<gpilqg::Matrix>* d_dx) const override;

 private:
  AcrobotParameters p_;
};

}  // namespace acrobot
