#include "gpilqg/core/cartpole.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "parameter_checks.hpp"

namespace gpilqg {

namespace {

using Mat2 = Eigen::Matrix2d;
using Vec2 = Eigen::Vector2d;

/// Mass matrix, its inverse and its derivative with respect to theta (the only coordinate it
/// depends on). det M = mp l^2 (mc + mp s^2) > 0 for positive masses and length.
struct MassMatrix {
  Mat2 M_inv;
  Mat2 dM_dtheta;
};

MassMatrix mass_matrix(const CartPoleParameters& p, double s, double c) {
  const double mc = p.cart_mass, mp = p.pole_mass, l = p.pole_length;
  const double det = mp * l * l * (mc + mp * s * s);
  MassMatrix out;
  out.M_inv << mp * l * l, -mp * l * c, -mp * l * c, mc + mp;
  out.M_inv /= det;
  out.dM_dtheta << 0.0, -mp * l * s, -mp * l * s, 0.0;
  return out;
}

}  // namespace

CartPole::CartPole(CartPoleParameters parameters) : p_(parameters) {
  parameter_checks::require_positive("cartpole", p_.cart_mass, "cart_mass");
  parameter_checks::require_positive("cartpole", p_.pole_mass, "pole_mass");
  parameter_checks::require_positive("cartpole", p_.pole_length, "pole_length");
  parameter_checks::require_positive("cartpole", p_.gravity, "gravity");
}

const std::string& CartPole::name() const {
  static const std::string kName = "cartpole";
  return kName;
}

const std::vector<Quantity>& CartPole::states() const {
  static const std::vector<Quantity> kStates = {
      {"x", "m"}, {"x_dot", "m/s"}, {"theta", "rad"}, {"theta_dot", "rad/s"}};
  return kStates;
}

const std::vector<Quantity>& CartPole::controls() const {
  static const std::vector<Quantity> kControls = {{"force", "N"}};
  return kControls;
}

std::vector<Parameter> CartPole::parameters() const {
  return {{"cart_mass", "kg", p_.cart_mass},
          {"pole_mass", "kg", p_.pole_mass},
          {"pole_length", "m", p_.pole_length},
          {"gravity", "m/s^2", p_.gravity}};
}

void CartPole::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                        DynamicsJacobians* jacobians) const {
  const double mp = p_.pole_mass, l = p_.pole_length, g = p_.gravity;
  const double theta = x(2), theta_dot = x(3), force = u(0);
  const double s = std::sin(theta), c = std::cos(theta);

  const MassMatrix mm = mass_matrix(p_, s, c);
  // h(q, q_dot, u): generalised forces (input, centrifugal, gravity).
  const Vec2 h(force + mp * l * s * theta_dot * theta_dot, -mp * g * l * s);
  const Vec2 q_ddot = mm.M_inv * h;

  xdot(0) = x(1);
  xdot(1) = q_ddot(0);
  xdot(2) = theta_dot;
  xdot(3) = q_ddot(1);
  if (!jacobians) return;

  // d q_ddot / d z = M^-1 (dh/dz - dM/dz q_ddot); only theta, theta_dot and u enter.
  const Vec2 dh_dtheta(mp * l * c * theta_dot * theta_dot, -mp * g * l * c);
  const Vec2 dqdd_dtheta = mm.M_inv * (dh_dtheta - mm.dM_dtheta * q_ddot);
  const Vec2 dqdd_dthetadot = mm.M_inv * Vec2(2.0 * mp * l * s * theta_dot, 0.0);
  const Vec2 dqdd_du = mm.M_inv.col(0);

  jacobians->resize(4, 1);
  Matrix& fx = jacobians->fx;
  fx.setZero();
  fx(0, 1) = 1.0;
  fx(2, 3) = 1.0;
  fx(1, 2) = dqdd_dtheta(0);
  fx(3, 2) = dqdd_dtheta(1);
  fx(1, 3) = dqdd_dthetadot(0);
  fx(3, 3) = dqdd_dthetadot(1);
  Matrix& fu = jacobians->fu;
  fu.setZero();
  fu(1, 0) = dqdd_du(0);
  fu(3, 0) = dqdd_du(1);
}

void CartPole::input_matrix(const VectorCRef& x, const VectorCRef&, InputMatrix& out) const {
  // b = [0, (M^-1 e1)_0, 0, (M^-1 e1)_1];  db/dtheta = -M^-1 dM/dtheta M^-1 e1;  db/du = 0.
  const double s = std::sin(x(2)), c = std::cos(x(2));
  const MassMatrix mm = mass_matrix(p_, s, c);
  const Vec2 b = mm.M_inv.col(0);
  const Vec2 db_dtheta = -mm.M_inv * (mm.dM_dtheta * b);
  out.resize(4, 1);
  out.b.setZero();
  out.b(1, 0) = b(0);
  out.b(3, 0) = b(1);
  out.d_dx[0].setZero();
  out.d_dx[0](1, 2) = db_dtheta(0);
  out.d_dx[0](3, 2) = db_dtheta(1);
  out.d_du[0].setZero();
}

const std::vector<Quantity>& CartPole::generalised_forces() const {
  static const std::vector<Quantity> kForces = {{"Q_x", "N"}, {"Q_theta", "N m"}};
  return kForces;
}

void CartPole::generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const {
  const double s = std::sin(x(2)), c = std::cos(x(2));
  const MassMatrix mm = mass_matrix(p_, s, c);
  W.setZero(4, 2);
  W.row(1) = mm.M_inv.row(0);
  W.row(3) = mm.M_inv.row(1);
  if (d_dx == nullptr) return;
  d_dx->resize(4);
  for (auto& d : *d_dx) d.setZero(4, 2);
  const Mat2 dM_inv = -mm.M_inv * mm.dM_dtheta * mm.M_inv;
  (*d_dx)[2].row(1) = dM_inv.row(0);
  (*d_dx)[2].row(3) = dM_inv.row(1);
}

double CartPole::energy(const VectorCRef& x) const {
  const double mc = p_.cart_mass, mp = p_.pole_mass, l = p_.pole_length, g = p_.gravity;
  const double x_dot = x(1), theta_dot = x(3), c = std::cos(x(2));
  const double kinetic = 0.5 * (mc + mp) * x_dot * x_dot + mp * l * c * x_dot * theta_dot +
                         0.5 * mp * l * l * theta_dot * theta_dot;
  const double potential = mp * g * l * (1.0 - c);
  return kinetic + potential;
}

}  // namespace gpilqg
