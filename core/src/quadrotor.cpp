#include "gpilqg/core/quadrotor.hpp"

#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "parameter_checks.hpp"

namespace gpilqg {

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

constexpr int kStateDim = 12;
constexpr int kControlDim = 4;
// First index of each 3-vector in the state.
constexpr int kP = 0, kV = 3, kR = 6, kW = 9;


/// Cross-product matrix [a], [a] b = a x b.
Mat3 hat(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a(2), a(1),  //
      a(2), 0.0, -a(0),   //
      -a(1), a(0), 0.0;
  return m;
}

// --------------------------------------------------------------------------------------------------
// Scalar coefficients of the rotation vector, t = |r|, all even functions of t (so functions of
// s = t^2, which needs no square root):
//
//   beta(t)  = (1 - cos t) / t^2              Rodrigues and J_l, coefficient of [r]
//   gamma(t) = (t - sin t) / t^3              J_l, coefficient of [r]^2
//   alpha(t) = sin t / t = 1 - t^2 gamma(t)   Rodrigues, coefficient of [r]
//   c(t)     = (1 - (t/2) cot(t/2)) / t^2     r_dot, coefficient of [r]^2 w
//   c'(t)/t                                   d c / d r = (c'(t)/t) r'
//
// The closed forms lose digits to cancellation as t -> 0: the error of c is ~ eps / t^2 relative, that
// of c'(t)/t ~ eps / t^4. Below kSeriesThreshold all five come from their Maclaurin series in t^2,
// each truncated where the first omitted term is below 2^-55 of the sum at t = kSeriesThreshold. For
// t^2 < 1 the series of c and c'/t have positive terms and those of beta and gamma shrink from the
// first, so Horner's rule is accurate to an ulp or two. The switch sits where the closed forms are good
// again: at t >= 1 alpha, beta, gamma are within 5e-16, c within 2e-15 relative (measured against
// 50-digit references), and c'/t within 2e-13 -- but c'/t only enters the Jacobian as (c'/t) t^2 next
// to 2c, so the entries of d r_dot / dr stay within ~3e-15 relative on both sides of the switch.
// tests/core/quadrotor_test.cpp checks c and c'/t on both sides against long-double closed forms.
// The series also spare the four trigonometric calls in the common case |r| < 1 rad.
//
// c(t) = sum_k |B_{2k+2}| / (2k+2)! t^{2k} (B_n Bernoulli numbers, from x cot x = 1 - sum_k
// 2^{2k} |B_{2k}| x^{2k} / (2k)!), and c'(t)/t = sum_k 2(k+1) |B_{2k+4}| / (2k+4)! t^{2k}. Both have
// radius of convergence 2 pi, where c has a pole: the rotation-vector kinematics are singular at
// |r| = 2 pi, and the model is meant for |r| < 2 pi.
constexpr double kSeriesThreshold = 1.0;  // [rad]

// (1 - cos t) / t^2 = sum_k (-1)^k t^{2k} / (2k+2)!
constexpr std::array<double, 10> kBetaSeries = {
    0.5,                      // 1/2
    -0.041666666666666664,    // -1/24
    0.001388888888888889,     // 1/720
    -2.48015873015873e-05,    // -1/40320
    2.755731922398589e-07,    // 1/3628800
    -2.08767569878681e-09,    // -1/479001600
    1.1470745597729725e-11,   // 1/87178291200
    -4.779477332387385e-14,   // -1/20922789888000
    1.5619206968586225e-16,   // 1/6402373705728000
    -4.110317623312165e-19,   // -1/2432902008176640000
};
// (t - sin t) / t^3 = sum_k (-1)^k t^{2k} / (2k+3)!
constexpr std::array<double, 10> kGammaSeries = {
    0.16666666666666666,      // 1/6
    -0.008333333333333333,    // -1/120
    0.0001984126984126984,    // 1/5040
    -2.7557319223985893e-06,  // -1/362880
    2.505210838544172e-08,    // 1/39916800
    -1.6059043836821613e-10,  // -1/6227020800
    7.647163731819816e-13,    // 1/1307674368000
    -2.8114572543455206e-15,  // -1/355687428096000
    8.22063524662433e-18,     // 1/121645100408832000
    -1.9572941063391263e-20,  // -1/51090942171709440000
};
// c(t) = sum_k |B_{2k+2}| / (2k+2)! t^{2k}
constexpr std::array<double, 12> kCSeries = {
    0.08333333333333333,      // 1/12
    0.001388888888888889,     // 1/720
    3.306878306878307e-05,    // 1/30240
    8.267195767195768e-07,    // 1/1209600
    2.08767569878681e-08,     // 1/47900160
    5.284190138687493e-10,    // 691/1307674368000
    1.3382536530684679e-11,   // 1/74724249600
    3.3896802963225827e-13,   // 3617/10670622842880000
    8.586062056277845e-15,    // 43867/5109094217170944000
    2.174868698558062e-16,    // 174611/802857662698291200000
    5.5090028283602295e-18,   // 77683/14101100039391805440000
    1.3954464685812522e-19,   // 236364091/1693824136731743669452800000
};
// c'(t) / t = sum_k 2(k+1) |B_{2k+4}| / (2k+4)! t^{2k}
constexpr std::array<double, 13> kCPrimeSeries = {
    0.002777777777777778,     // 1/360
    0.00013227513227513228,   // 1/7560
    4.96031746031746e-06,     // 1/201600
    1.670140559029448e-07,    // 1/5987520
    5.2841901386874934e-09,   // 691/130767436800
    1.6059043836821613e-10,   // 1/6227020800
    4.745552414851616e-12,    // 3617/762187345920000
    1.3737699290044552e-13,   // 43867/319318388573184000
    3.914763657404511e-15,    // 174611/44603203483238400000
    1.1018005656720459e-16,   // 77683/705055001969590272000
    3.069982230878755e-18,    // 236364091/76992006215079257702400000
    8.483296895110721e-20,    // 657931/7755605021665492992000000
    2.327914531029762e-21,    // 3392780147/1457433295671379443056640000000
};

template <std::size_t N>
double horner(const std::array<double, N>& coefficients, double s) {
  double sum = coefficients[N - 1];
  for (std::size_t k = N - 1; k-- > 0;) sum = sum * s + coefficients[k];
  return sum;
}

struct RotationCoefficients {
  double alpha;    // sin t / t
  double beta;     // (1 - cos t) / t^2
  double gamma;    // (t - sin t) / t^3
  double c;        // (1 - (t/2) cot(t/2)) / t^2
  double c_prime;  // c'(t) / t
};

RotationCoefficients rotation_coefficients(double t_squared) {
  RotationCoefficients k;
  const double s = t_squared;
  if (s < kSeriesThreshold * kSeriesThreshold) {
    k.beta = horner(kBetaSeries, s);
    k.gamma = horner(kGammaSeries, s);
    k.alpha = 1.0 - s * k.gamma;
    k.c = horner(kCSeries, s);
    k.c_prime = horner(kCPrimeSeries, s);
    return k;
  }
  const double t = std::sqrt(s);
  const double half = 0.5 * t;
  const double sin_t = std::sin(t);
  const double sin_half = std::sin(half), cos_half = std::cos(half);
  k.alpha = sin_t / t;
  k.beta = 2.0 * (sin_half / t) * (sin_half / t);  // 1 - cos t = 2 sin^2(t/2): no cancellation
  k.gamma = (t - sin_t) / (s * t);
  // h = (t/2) cot(t/2);  c = (1 - h) / t^2;  c'/t = (h + (t/2)^2 / sin^2(t/2) - 2) / t^4
  const double h = half * cos_half / sin_half;
  const double q = half / sin_half;
  k.c = (1.0 - h) / s;
  k.c_prime = (h + q * q - 2.0) / (s * s);
  return k;
}

/// Thrust direction R(r) e3 = e3 + alpha [r] e3 + beta [r]^2 e3 and its Jacobian
/// d(R e3)/dr = -[R e3] J_l(r), J_l(r) = I + beta [r] + gamma [r]^2 (left Jacobian of SO(3)).
Vec3 thrust_direction(const Vec3& r, const RotationCoefficients& k) {
  // [r] e3 = (ry, -rx, 0);  [r]^2 e3 = r rz - |r|^2 e3.
  return Vec3(k.alpha * r(1) + k.beta * r(0) * r(2), -k.alpha * r(0) + k.beta * r(1) * r(2),
              1.0 - k.beta * (r(0) * r(0) + r(1) * r(1)));
}

Mat3 thrust_direction_jacobian(const Vec3& r, double t_squared, const Vec3& thrust,
                               const RotationCoefficients& k) {
  Mat3 jl = k.gamma * (r * r.transpose());  // [r]^2 = r r' - |r|^2 I
  jl.diagonal().array() += 1.0 - k.gamma * t_squared;
  jl += k.beta * hat(r);
  return -hat(thrust) * jl;
}

/// b = f_u (12 x 4, already sized): column j is (0, R(r) e3 / m, 0, tau_j / J) with tau_j the body
/// torque per newton of rotor j: tau_1 = (0, -rho, km), tau_2 = (rho, 0, -km), tau_3 = (0, rho, km),
/// tau_4 = (-rho, 0, -km).
void write_input_matrix(const QuadrotorParameters& p, const Vec3& thrust, Matrix& b) {
  const double rho_j = p.rho / p.inertia, km_j = p.km / p.inertia;
  b.setZero();
  b.block<3, 4>(kV, 0) = (thrust / p.mass).replicate<1, 4>();
  b(kW + 0, 1) = rho_j;
  b(kW + 0, 3) = -rho_j;
  b(kW + 1, 0) = -rho_j;
  b(kW + 1, 2) = rho_j;
  b(kW + 2, 0) = km_j;
  b(kW + 2, 1) = -km_j;
  b(kW + 2, 2) = km_j;
  b(kW + 2, 3) = -km_j;
}

}  // namespace

Quadrotor::Quadrotor(QuadrotorParameters parameters) : p_(parameters) {
  parameter_checks::require_positive("quadrotor", p_.mass, "mass");
  parameter_checks::require_non_negative("quadrotor", p_.kv, "kv");
  parameter_checks::require_non_negative("quadrotor", p_.km, "km");
  parameter_checks::require_positive("quadrotor", p_.inertia, "inertia");
  parameter_checks::require_positive("quadrotor", p_.rho, "rho");
  parameter_checks::require_positive("quadrotor", p_.gravity, "gravity");
}

const std::string& Quadrotor::name() const {
  static const std::string kName = "quadrotor";
  return kName;
}

const std::vector<Quantity>& Quadrotor::states() const {
  static const std::vector<Quantity> kStates = {
      {"px", "m"},   {"py", "m"},   {"pz", "m"},   {"vx", "m/s"},   {"vy", "m/s"},   {"vz", "m/s"},
      {"rx", "rad"}, {"ry", "rad"}, {"rz", "rad"}, {"wx", "rad/s"}, {"wy", "rad/s"}, {"wz", "rad/s"}};
  return kStates;
}

const std::vector<Quantity>& Quadrotor::controls() const {
  static const std::vector<Quantity> kControls = {{"u1", "N"}, {"u2", "N"}, {"u3", "N"}, {"u4", "N"}};
  return kControls;
}

std::vector<Parameter> Quadrotor::parameters() const {
  return {{"mass", "kg", p_.mass},
          {"kv", "N s/m", p_.kv},
          {"km", "m", p_.km},
          {"inertia", "kg m^2", p_.inertia},
          {"rho", "m", p_.rho},
          {"gravity", "m/s^2", p_.gravity}};
}

void Quadrotor::evaluate(const VectorCRef& x, const VectorCRef& u, VectorRef xdot,
                         DynamicsJacobians* jacobians) const {
  assert(x.size() == kStateDim && u.size() == kControlDim && xdot.size() == kStateDim);
  const double m = p_.mass, j = p_.inertia;
  const Vec3 v = x.segment<3>(kV), r = x.segment<3>(kR), w = x.segment<3>(kW);
  const double thrust_sum = u(0) + u(1) + u(2) + u(3);

  const double t_squared = r.squaredNorm();
  const RotationCoefficients k = rotation_coefficients(t_squared);
  const Vec3 thrust = thrust_direction(r, k);  // R(r) e3
  const double r_dot_w = r.dot(w);
  const Vec3 rr_w = r * r_dot_w - t_squared * w;  // [r]^2 w

  xdot.segment<3>(kP) = v;
  xdot.segment<3>(kV) = (thrust_sum * thrust - p_.kv * v) / m;
  xdot(kV + 2) -= p_.gravity;
  xdot.segment<3>(kR) = w + 0.5 * r.cross(w) + k.c * rr_w;
  // Body torques over J. With J = inertia I the gyroscopic term [w] J w = inertia (w x w) vanishes
  // identically, so it is left out (and d w_dot / d w = 0).
  xdot(kW + 0) = p_.rho * (u(1) - u(3)) / j;
  xdot(kW + 1) = p_.rho * (u(2) - u(0)) / j;
  xdot(kW + 2) = p_.km * (u(0) - u(1) + u(2) - u(3)) / j;
  if (!jacobians) return;

  jacobians->resize(kStateDim, kControlDim);
  Matrix& fx = jacobians->fx;
  fx.setZero();
  // p_dot = v
  fx.block<3, 3>(kP, kV).diagonal().setOnes();
  // v_dot: drag and the thrust direction's dependence on r.
  fx.block<3, 3>(kV, kV).diagonal().setConstant(-p_.kv / m);
  fx.block<3, 3>(kV, kR) = (thrust_sum / m) * thrust_direction_jacobian(r, t_squared, thrust, k);
  // r_dot = w + 1/2 [r] w + c(|r|) [r]^2 w:
  //   d/dr = -1/2 [w] + c (r.w I + r w' - 2 w r') + (c'(t)/t) [r]^2 w r'
  //   d/dw = I + 1/2 [r] + c [r]^2
  Mat3 d_dr = k.c * (r * w.transpose() - 2.0 * w * r.transpose()) - 0.5 * hat(w);
  d_dr.diagonal().array() += k.c * r_dot_w;
  d_dr.noalias() += k.c_prime * rr_w * r.transpose();
  fx.block<3, 3>(kR, kR) = d_dr;
  Mat3 d_dw = k.c * (r * r.transpose()) + 0.5 * hat(r);
  d_dw.diagonal().array() += 1.0 - k.c * t_squared;
  fx.block<3, 3>(kR, kW) = d_dw;

  write_input_matrix(p_, thrust, jacobians->fu);
}

const std::vector<Quantity>& Quadrotor::generalised_forces() const {
  static const std::vector<Quantity> kForces = {{"F_x", "N"},   {"F_y", "N"},   {"F_z", "N"},
                                                {"tau_x", "N m"}, {"tau_y", "N m"}, {"tau_z", "N m"}};
  return kForces;
}

void Quadrotor::generalised_force_map(const VectorCRef& x, Matrix& W, std::vector<Matrix>* d_dx) const {
  assert(x.size() == kStateDim);
  static_cast<void>(x);
  W.setZero(kStateDim, 6);
  W.block<3, 3>(kV, 0).diagonal().setConstant(1.0 / p_.mass);
  W.block<3, 3>(kW, 3).diagonal().setConstant(1.0 / p_.inertia);
  if (d_dx == nullptr) return;
  d_dx->resize(kStateDim);
  for (auto& d : *d_dx) d.setZero(kStateDim, 6);
}

std::vector<GeneralisedCoordinate> Quadrotor::coordinates() const {
  const char* axes[] = {"x", "y", "z"};
  std::vector<GeneralisedCoordinate> out;
  for (int i = 0; i < 3; ++i)
    out.push_back({std::string("p") + axes[i], std::string("F_") + axes[i], i, kP + i, kV + i});
  for (int i = 0; i < 3; ++i)
    out.push_back({std::string("r") + axes[i], std::string("tau_") + axes[i], 3 + i, kR + i, kW + i});
  return out;
}

void Quadrotor::input_matrix(const VectorCRef& x, const VectorCRef& u, InputMatrix& out) const {
  // b = f_u: column j is (0, R(r) e3 / m, 0, torque_j / J), independent of u. Only the thrust part
  // depends on x, through r: d b_j / dr = d(R e3)/dr / m, the same for all four columns; d b_j / du = 0.
  assert(x.size() == kStateDim && u.size() == kControlDim);
  static_cast<void>(u);
  const Vec3 r = x.segment<3>(kR);
  const double t_squared = r.squaredNorm();
  const RotationCoefficients k = rotation_coefficients(t_squared);
  const Vec3 thrust = thrust_direction(r, k);
  const Mat3 d_thrust = thrust_direction_jacobian(r, t_squared, thrust, k) / p_.mass;

  out.resize(kStateDim, kControlDim);
  write_input_matrix(p_, thrust, out.b);
  for (int j = 0; j < kControlDim; ++j) {
    Matrix& d_dx = out.d_dx[static_cast<std::size_t>(j)];
    d_dx.setZero();
    d_dx.block<3, 3>(kV, kR) = d_thrust;
    out.d_du[static_cast<std::size_t>(j)].setZero();
  }
}

}  // namespace gpilqg
