#include "acrobot.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace acrobot {

namespace {

using gpilqg::Matrix;
using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;

void require_positive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string("acrobot parameter '") + name + "' = " + std::to_string(value) +
                                "; expected a finite value > 0");
}

/// The rods' centres of mass and inertias about their own joints.
struct Rods {
  double lc1, lc2, I1, I2, a;  ///< a = m2 l1 lc2
};

Rods rods(const AcrobotParameters& p) {
  const double lc1 = 0.5 * p.link1_length, lc2 = 0.5 * p.link2_length;
  return {lc1, lc2, p.link1_mass * p.link1_length * p.link1_length / 3.0,
          p.link2_mass * p.link2_length * p.link2_length / 3.0, p.link2_mass * p.link1_length * lc2};
}

/// M(theta2), its inverse and dM/dtheta2. det M = I1 I2 + m2 l1^2 I2 - a^2 c2^2 > 0 for any theta2,
/// since m2 l1^2 I2 = m2^2 l1^2 l2^2 / 3 exceeds a^2 = m2^2 l1^2 l2^2 / 4.
struct MassMatrix {
  Mat2 M;
  Mat2 M_inv;
  Mat2 dM_dtheta2;
};

MassMatrix mass_matrix(const AcrobotParameters& p, const Rods& r, double s2, double c2) {
  MassMatrix out;
  const double m12 = r.I2 + r.a * c2;
  out.M << r.I1 + r.I2 + p.link2_mass * p.link1_length * p.link1_length + 2.0 * r.a * c2, m12, m12, r.I2;
  out.M_inv = out.M.inverse();
  out.dM_dtheta2 << -2.0 * r.a * s2, -r.a * s2, -r.a * s2, 0.0;
  return out;
}

}  // namespace

Acrobot::Acrobot(AcrobotParameters parameters) : p_(parameters) {
  require_positive(p_.link1_mass, "link1_mass");
  require_positive(p_.link2_mass, "link2_mass");
  require_positive(p_.link1_length, "link1_length");
  require_positive(p_.link2_length, "link2_length");
  require_positive(p_.gravity, "gravity");
}

const std::string& Acrobot::name() const {
  static const std::string kName = "acrobot";
  return kName;
}

const std::vector<gpilqg::Quantity>& Acrobot::states() const {
  static const std::vector<gpilqg::Quantity> kStates = {
      {"theta1", "rad"}, {"theta2", "rad"}, {"theta1_dot", "rad/s"}, {"theta2_dot", "rad/s"}};
  return kStates;
}

const std::vector<gpilqg::Quantity>& Acrobot::controls() const {
  static const std::vector<gpilqg::Quantity> kControls = {{"tau", "N m"}};
  return kControls;
}

std::vector<gpilqg::Parameter> Acrobot::parameters() const {
  return {{"link1_mass", "kg", p_.link1_mass},
          {"link2_mass", "kg", p_.link2_mass},
          {"link1_length", "m", p_.link1_length},
          {"link2_length", "m", p_.link2_length},
          {"gravity", "m/s^2", p_.gravity}};
}

void Acrobot::evaluate(const gpilqg::VectorCRef& x, const gpilqg::VectorCRef& u, gpilqg::VectorRef xdot,
                       gpilqg::DynamicsJacobians* jacobians) const {
  const Rods r = rods(p_);
  const double m1 = p_.link1_mass, m2 = p_.link2_mass, l1 = p_.link1_length, g = p_.gravity;
  const double qd1 = x(2), qd2 = x(3);
  const double s1 = std::sin(x(0)), c1 = std::cos(x(0));
  const double s2 = std::sin(x(1)), c2 = std::cos(x(1));
  const double s12 = std::sin(x(0) + x(1)), c12 = std::cos(x(0) + x(1));

  const MassMatrix mm = mass_matrix(p_, r, s2, c2);
  const Vec2 h(-m1 * g * r.lc1 * s1 - m2 * g * (l1 * s1 + r.lc2 * s12) + r.a * s2 * (2.0 * qd1 * qd2 + qd2 * qd2),
               u(0) - m2 * g * r.lc2 * s12 - r.a * s2 * qd1 * qd1);
  const Vec2 q_ddot = mm.M_inv * h;

  xdot(0) = qd1;
  xdot(1) = qd2;
  xdot(2) = q_ddot(0);
  xdot(3) = q_ddot(1);
  if (jacobians == nullptr) return;

  // d q_ddot / d z = M^-1 (dh/dz - dM/dz q_ddot); only theta2 enters M.
  const Vec2 dh_dtheta1(-m1 * g * r.lc1 * c1 - m2 * g * (l1 * c1 + r.lc2 * c12), -m2 * g * r.lc2 * c12);
  const Vec2 dh_dtheta2(-m2 * g * r.lc2 * c12 + r.a * c2 * (2.0 * qd1 * qd2 + qd2 * qd2),
                        -m2 * g * r.lc2 * c12 - r.a * c2 * qd1 * qd1);
  const Vec2 dh_dqd1(2.0 * r.a * s2 * qd2, -2.0 * r.a * s2 * qd1);
  const Vec2 dh_dqd2(2.0 * r.a * s2 * (qd1 + qd2), 0.0);

  jacobians->resize(4, 1);
  Matrix& fx = jacobians->fx;
  fx.setZero();
  fx(0, 2) = 1.0;
  fx(1, 3) = 1.0;
  fx.block<2, 1>(2, 0) = mm.M_inv * dh_dtheta1;
  fx.block<2, 1>(2, 1) = mm.M_inv * (dh_dtheta2 - mm.dM_dtheta2 * q_ddot);
  fx.block<2, 1>(2, 2) = mm.M_inv * dh_dqd1;
  fx.block<2, 1>(2, 3) = mm.M_inv * dh_dqd2;
  Matrix& fu = jacobians->fu;
  fu.setZero();
  fu.block<2, 1>(2, 0) = mm.M_inv.col(1);
}

void Acrobot::input_matrix(const gpilqg::VectorCRef& x, const gpilqg::VectorCRef&, gpilqg::InputMatrix& out) const {
  const MassMatrix mm = mass_matrix(p_, rods(p_), std::sin(x(1)), std::cos(x(1)));
  const Vec2 b = mm.M_inv.col(1);
  out.resize(4, 1);
  out.b.setZero();
  out.b.block<2, 1>(2, 0) = b;
  out.d_dx[0].setZero();
  out.d_dx[0].block<2, 1>(2, 1) = -mm.M_inv * (mm.dM_dtheta2 * b);
  out.d_du[0].setZero();
}

double Acrobot::energy(const gpilqg::VectorCRef& x) const {
  const Rods r = rods(p_);
  const double m1 = p_.link1_mass, m2 = p_.link2_mass, l1 = p_.link1_length, g = p_.gravity;
  const MassMatrix mm = mass_matrix(p_, r, std::sin(x(1)), std::cos(x(1)));
  const Vec2 qd(x(2), x(3));
  const double kinetic = 0.5 * qd.dot(mm.M * qd);
  const double c1 = std::cos(x(0)), c12 = std::cos(x(0) + x(1));
  const double potential = m1 * g * r.lc1 * (1.0 - c1) + m2 * g * (l1 * (1.0 - c1) + r.lc2 * (1.0 - c12));
  return kinetic + potential;
}

const std::vector<gpilqg::Quantity>& Acrobot::generalised_forces() const {
  static const std::vector<gpilqg::Quantity> kForces = {{"Q_theta1", "N m"}, {"Q_theta2", "N m"}};
  return kForces;
}

void Acrobot::generalised_force_map(const gpilqg::VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const {
  const MassMatrix mm = mass_matrix(p_, rods(p_), std::sin(x(1)), std::cos(x(1)));
  W.setZero(4, 2);
  W.block<2, 2>(2, 0) = mm.M_inv;
  if (d_dx == nullptr) return;
  d_dx->resize(4);
  for (Matrix& d : *d_dx) d.setZero(4, 2);
  (*d_dx)[1].block<2, 2>(2, 0) = -mm.M_inv * mm.dM_dtheta2 * mm.M_inv;
}

}  // namespace acrobot
