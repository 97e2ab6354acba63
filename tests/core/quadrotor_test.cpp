// Quadrotor: analytic Jacobians and input matrix against central differences (including r = 0 and
// both sides of the series switch at |r| = 1), hover and pure-yaw sanity, the rotation and the
// attitude kinematics against Eigen's independent AngleAxis, the coefficient c(|r|) of r_dot and its
// derivative against long-double closed forms and their series, the presets and parameter validation.

#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/quadrotor.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// |r| below which quadrotor.cpp evaluates the rotation coefficients by their series.
constexpr double kSeriesSwitch = 1.0;
constexpr double kEps = std::numeric_limits<double>::epsilon();

constexpr int kV = 3, kR = 6, kW = 9;

Vec3 unit(const Vec3& a) { return a / a.norm(); }

/// Rotation about r / |r| by |r| from Eigen's AngleAxis (an implementation independent of ours).
Mat3 rotation(const Vec3& r) {
  const double t = r.norm();
  if (t == 0.0) return Mat3::Identity();
  return Eigen::AngleAxisd(t, r / t).toRotationMatrix();
}

Mat3 hat(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a(2), a(1), a(2), 0.0, -a(0), -a(1), a(0), 0.0;
  return m;
}

Vector state(const Vec3& p, const Vec3& v, const Vec3& r, const Vec3& w) {
  Vector x(12);
  x << p, v, r, w;
  return x;
}

/// Random states with r spread over directions and |r| in [0, 2.5] rad.
Vector random_state(unsigned seed) {
  Vector x = test::random_vector(12, -3.0, 3.0, seed);
  const double t = 2.5 * test::random_vector(1, 0.0, 1.0, 500 + seed)(0);
  x.segment<3>(kR) = t * unit(x.segment<3>(kR));
  return x;
}

/// States at the special attitudes: r = 0, tiny |r|, and |r| just below and above the series switch.
std::vector<Vector> special_states() {
  const std::vector<double> norms = {0.0,
                                     1e-300,
                                     1e-9,
                                     1e-5,
                                     1e-2,
                                     0.5,
                                     kSeriesSwitch * (1.0 - 1e-3),
                                     kSeriesSwitch * (1.0 - 1e-12),
                                     kSeriesSwitch,
                                     kSeriesSwitch * (1.0 + 1e-12),
                                     kSeriesSwitch * (1.0 + 1e-3),
                                     2.0,
                                     3.0};
  std::vector<Vector> out;
  unsigned seed = 900;
  for (double t : norms) {
    Vector x = test::random_vector(12, -2.0, 2.0, seed++);
    x.segment<3>(kR) = t * unit(x.segment<3>(kR));
    out.push_back(x);
  }
  return out;
}

std::vector<Vector> test_states() {
  std::vector<Vector> out = special_states();
  for (unsigned seed = 0; seed < 25; ++seed) out.push_back(random_state(seed));
  return out;
}

/// Rotor forces around hover, uniform in [0.2, 1.8] times the hover force.
Vector random_controls(const Quadrotor& quad, unsigned seed) {
  return quad.hover_force() * test::random_vector(4, 0.2, 1.8, 2000 + seed);
}

TEST(Quadrotor, AnalyticJacobiansMatchCentralDifferences) {
  for (const auto& params : {QuadrotorParameters::simulator(), QuadrotorParameters::real_world(),
                             QuadrotorParameters{1.3, 0.4, 0.05, 0.02, 0.25, 9.81}}) {
    const Quadrotor quad(params);
    unsigned seed = 0;
    for (const Vector& x : test_states()) {
      const Vector u = random_controls(quad, seed++);
      DynamicsJacobians jac;
      Vector xdot(12);
      quad.evaluate(x, u, xdot, &jac);
      const Matrix fx = test::numeric_jacobian([&](const Vector& xs) { return quad.f(xs, u); }, x, test::kFdStep);
      const Matrix fu = test::numeric_jacobian([&](const Vector& us) { return quad.f(x, us); }, u, test::kFdStep);
      const double scale = std::max(1.0, xdot.cwiseAbs().maxCoeff());
      EXPECT_TRUE(test::matrices_near(jac.fx, fx, test::kFdTolerance * scale, test::kFdTolerance))
          << "|r| = " << x.segment<3>(kR).norm() << ", x = " << x.transpose();
      EXPECT_TRUE(test::matrices_near(jac.fu, fu, test::kFdTolerance * scale, test::kFdTolerance))
          << "|r| = " << x.segment<3>(kR).norm() << ", x = " << x.transpose();
      EXPECT_MATRIX_NEAR(xdot, quad.f(x, u), 0.0);  // the Jacobian path does not change f
    }
  }
}

TEST(Quadrotor, JacobiansAreWrittenIntoWronglySizedBuffers) {
  const Quadrotor quad;
  DynamicsJacobians jac;
  jac.fx = Matrix::Constant(3, 5, 7.0);
  jac.fu = Matrix::Constant(12, 4, 7.0);
  Vector xdot(12);
  const Vector x = random_state(3), u = random_controls(quad, 3);
  quad.evaluate(x, u, xdot, &jac);
  DynamicsJacobians fresh;
  fresh.resize(12, 4);
  quad.evaluate(x, u, xdot, &fresh);
  EXPECT_MATRIX_NEAR(jac.fx, fresh.fx, 0.0);
  EXPECT_MATRIX_NEAR(jac.fu, fresh.fu, 0.0);
}

TEST(Quadrotor, InputMatrixIsFuAndItsDerivativeMatchesCentralDifferences) {
  const Quadrotor quad(QuadrotorParameters::real_world());
  unsigned seed = 0;
  for (const Vector& x : test_states()) {
    const Vector u = random_controls(quad, seed++);
    InputMatrix b;
    quad.input_matrix(x, u, b);
    DynamicsJacobians jac;
    Vector xdot(12);
    quad.evaluate(x, u, xdot, &jac);
    EXPECT_MATRIX_NEAR(b.b, jac.fu, 0.0);
    ASSERT_EQ(b.d_dx.size(), 4u);
    ASSERT_EQ(b.d_du.size(), 4u);
    for (int j = 0; j < 4; ++j) {
      const Matrix db = test::numeric_jacobian(
          [&](const Vector& xs) {
            DynamicsJacobians jj;
            Vector f(12);
            quad.evaluate(xs, u, f, &jj);
            return Vector(jj.fu.col(j));
          },
          x, test::kFdStep);
      // fu is O(1) (|R e3| / m, rho / J), so the round-off of the differences is ~eps / h.
      EXPECT_MATRIX_NEAR(b.d_dx[static_cast<std::size_t>(j)], db, test::kFdTolerance);
      EXPECT_MATRIX_NEAR(b.d_du[static_cast<std::size_t>(j)], Matrix::Zero(12, 4), 0.0);
    }
  }
}

TEST(Quadrotor, HoverIsAnEquilibriumAtAnyPosition) {
  for (const auto& params : {QuadrotorParameters::simulator(), QuadrotorParameters::real_world()}) {
    const Quadrotor quad(params);
    EXPECT_DOUBLE_EQ(quad.hover_force(), params.mass * 9.81 / 4.0);
    const Vector u = Vector::Constant(4, quad.hover_force());
    for (unsigned seed = 0; seed < 5; ++seed) {
      Vector x = Vector::Zero(12);
      x.head<3>() = test::random_vector(3, -10.0, 10.0, seed);
      // Exact for both presets: m g / 4 summed four times and divided by m rounds back to g (other
      // masses could leave an ulp of g, 2e-15).
      EXPECT_MATRIX_NEAR(quad.f(x, u), Vector::Zero(12), 0.0) << "mass " << params.mass;
    }
  }
}

TEST(Quadrotor, PureYawTorqueSpinsAboutTheVerticalAxisOnly) {
  const auto quad = std::make_shared<Quadrotor>();
  const double d = 0.1;
  Vector u = Vector::Constant(4, quad->hover_force());
  u += Eigen::Vector4d(d, -d, d, -d);

  Vector x = Vector::Zero(12);
  x.head<3>() << 1.0, -2.0, 5.0;
  const Vector xdot = quad->f(x, u);
  const double yaw_acceleration = 4.0 * quad->physical().km * d / quad->physical().inertia;
  Vector expected = Vector::Zero(12);
  expected(kW + 2) = yaw_acceleration;  // km (u1 - u2 + u3 - u4) / J = 4 km d / J, positive
  EXPECT_MATRIX_NEAR(xdot, expected, 1e-14);
  EXPECT_GT(yaw_acceleration, 0.0);

  // Two seconds of RK4: the attitude stays a rotation about z, the thrust vertical, the body in place.
  const IntegratedStepModel model(quad, Integrator::RK4, 0.01);
  Vector next(12);
  for (int k = 0; k < 200; ++k) {
    model.step(x, u, next);
    x = next;
  }
  const double duration = 2.0;
  EXPECT_NEAR(x(kW + 2), yaw_acceleration * duration, 1e-12);
  EXPECT_NEAR(x(kR + 2), 0.5 * yaw_acceleration * duration * duration, 1e-12);  // r_dot = w about z
  EXPECT_EQ(x(kR + 0), 0.0);
  EXPECT_EQ(x(kR + 1), 0.0);
  EXPECT_MATRIX_NEAR(x.segment<2>(kW), Vector::Zero(2), 0.0);
  EXPECT_MATRIX_NEAR(x.head<3>(), Vector(Eigen::Vector3d(1.0, -2.0, 5.0)), 1e-12);
  EXPECT_MATRIX_NEAR(x.segment<3>(kV), Vector::Zero(3), 1e-12);
}

TEST(Quadrotor, ThrustDirectionIsTheRotatedBodyAxisOfAngleAxis) {
  // v_dot + g e3 = (S R(r) e3 - kv v) / m; with v = 0 this isolates R(r) e3.
  const Quadrotor quad;
  const double m = quad.physical().mass, g = quad.physical().gravity;
  std::vector<Vector> states = test_states();
  states.push_back(state(Vec3::Zero(), Vec3::Zero(), Vec3(0.0, 0.0, 2.0), Vec3::Zero()));  // pure yaw
  states.push_back(state(Vec3::Zero(), Vec3::Zero(), Vec3(std::numbers::pi / 2, 0.0, 0.0), Vec3::Zero()));
  unsigned seed = 0;
  for (Vector x : states) {
    x.segment<3>(kV).setZero();
    const Vector u = random_controls(quad, seed++);
    const double thrust = u.sum();
    Vector v_dot = quad.f(x, u).segment<3>(kV);
    v_dot(2) += g;
    const Vec3 expected = thrust / m * rotation(x.segment<3>(kR)).col(2);
    // A few roundings of S / m ~ 20 m/s^2 (both Rodrigues branches and the Taylor series).
    EXPECT_MATRIX_NEAR(v_dot, Vector(expected), 8.0 * kEps * thrust / m)
        << "|r| = " << x.segment<3>(kR).norm();
  }
}

TEST(Quadrotor, DragOpposesVelocity) {
  const Quadrotor quad;
  const Vector u = Vector::Constant(4, quad.hover_force());
  const Vec3 v(1.0, -2.0, 0.5);
  const Vector xdot = quad.f(state(Vec3::Zero(), v, Vec3::Zero(), Vec3::Zero()), u);
  EXPECT_MATRIX_NEAR(xdot.segment<3>(kV), Vector(-quad.physical().kv / quad.physical().mass * v), 1e-14);
  EXPECT_MATRIX_NEAR(xdot.head<3>(), Vector(v), 0.0);
}

TEST(Quadrotor, RollAndPitchTorquesFollowTheRotorLayout) {
  // rho (u2 - u4) about x and rho (u3 - u1) about y: rotors 1 and 3 sit on the body x axis (at +rho
  // and -rho), 2 and 4 on the y axis; 1 and 3 spin the other way round from 2 and 4 (yaw sign km).
  const Quadrotor quad;
  const double rho = quad.physical().rho, j = quad.physical().inertia, km = quad.physical().km;
  const Vector u = Eigen::Vector4d(1.0, 2.0, 4.0, 8.0);
  const Vector w_dot = quad.f(Vector::Zero(12), u).segment<3>(kW);
  EXPECT_NEAR(w_dot(0), rho * (2.0 - 8.0) / j, 1e-14);
  EXPECT_NEAR(w_dot(1), rho * (4.0 - 1.0) / j, 1e-14);
  EXPECT_NEAR(w_dot(2), km * (1.0 - 2.0 + 4.0 - 8.0) / j, 1e-14);
}

TEST(Quadrotor, AttitudeRateIsTheBodyFrameAngularVelocity) {
  // r_dot = w + 1/2 [r] w + c [r]^2 w is J_r(r)^-1 w, the rotation-vector rate of R_dot = R [w] with w
  // in the body frame. One step: R(r + h r_dot) = R(r) exp(h [w]) + O(h^2), while the world-frame
  // reading exp(h [w]) R(r) is off at O(h).
  const Quadrotor quad;
  const Vector u = Vector::Constant(4, quad.hover_force());  // no torque: w stays constant
  for (unsigned seed = 0; seed < 20; ++seed) {
    const Vector x = random_state(seed);
    const Vec3 r = x.segment<3>(kR), w = x.segment<3>(kW);
    const Vec3 r_dot = quad.f(x, u).segment<3>(kR);
    double previous = 0.0;
    for (double h : {1e-3, 5e-4}) {
      const Mat3 stepped = rotation(r + h * r_dot);
      const double body = (stepped - rotation(r) * rotation(h * w)).norm();
      const double world = (stepped - rotation(h * w) * rotation(r)).norm();
      EXPECT_LT(body, 10.0 * h * h * (1.0 + w.squaredNorm() + r_dot.squaredNorm())) << "seed " << seed;
      if (r.cross(w).norm() > 0.1) {
        EXPECT_GT(world, 10.0 * body) << "seed " << seed;
      }
      if (previous > 0.0) {
        EXPECT_NEAR(previous / body, 4.0, 0.2) << "seed " << seed;  // O(h^2)
      }
      previous = body;
    }
  }
}

TEST(Quadrotor, IntegratedAttitudeFollowsTheBodyRateExactly) {
  // With no torque w is constant and R(t) = R(0) exp(t [w]) exactly; integrating the model's r_dot
  // with RK4 (global error ~ dt^4) must reproduce it, also through |r| = 0 and across the series switch.
  const auto quad = std::make_shared<Quadrotor>();
  const Vector u = Vector::Constant(4, quad->hover_force());
  const IntegratedStepModel model(quad, Integrator::RK4, 1e-3);
  std::vector<Vector> starts;
  for (unsigned seed = 0; seed < 8; ++seed) {
    Vector x = random_state(seed);
    x.segment<3>(kR) *= 0.6;  // |r| <= 1.5, |w| <= 3 sqrt(3): |r| stays well below 2 pi
    starts.push_back(x);
  }
  // Through r = 0: start at r = -0.25 w so the attitude passes the identity at t = 0.25 s.
  starts.push_back(state(Vec3::Zero(), Vec3::Zero(), Vec3(-0.1, 0.2, -0.05), Vec3(0.4, -0.8, 0.2)));
  for (const Vector& x0 : starts) {
    Vector x = x0, next(12);
    for (int k = 0; k < 500; ++k) {
      model.step(x, u, next);
      x = next;
    }
    const Mat3 expected = rotation(x0.segment<3>(kR)) * rotation(0.5 * x0.segment<3>(kW));
    EXPECT_TRUE(test::matrices_near(rotation(x.segment<3>(kR)), expected, 1e-10))
        << "r0 = " << x0.segment<3>(kR).transpose() << ", w = " << x0.segment<3>(kW).transpose();
  }
}

// ----------------------------------------------------------------------------------------------
// The coefficient c(t) = (1 - (t/2) cot(t/2)) / t^2 of [r]^2 w and c'(t)/t, read back from the
// Jacobian. With r = (r0, r1, 0) the entry d r_dot_x / d w_y = (1/2 [r] + c [r]^2)_{01} = c r0 r1 (the
// [r] entry is -r2 = 0), so c comes out to an ulp or two. With w = e3 (perpendicular to r),
// d r_dot_z / d r_x = -(2 c + (c'/t) t^2) r0: c'/t comes out with an absolute error ~ eps c / t^2.

struct CCoefficients {
  double c;
  double c_prime_over_t;
};

CCoefficients read_c(const Quadrotor& quad, double t) {
  const Vec3 r(0.6 * t, 0.8 * t, 0.0);
  const Vector x = state(Vec3::Zero(), Vec3::Zero(), r, Vec3(0.0, 0.0, 1.0));
  DynamicsJacobians jac;
  Vector xdot(12);
  quad.evaluate(x, Vector::Constant(4, 1.0), xdot, &jac);
  const double c = jac.fx(kR + 0, kW + 1) / (r(0) * r(1));
  const double t2 = r.squaredNorm();
  return {c, (-jac.fx(kR + 2, kR + 0) / r(0) - 2.0 * c) / t2};
}

/// Long-double closed forms: with a 64-bit mantissa (eps ~ 1.1e-19) their cancellation, ~ eps / t^2
/// for c and ~ eps / t^4 for c'/t, stays below 1e-15 for t >= 0.05 and t >= 0.5 respectively.
long double c_closed(long double t) {
  const long double half = t / 2;
  return (1.0L - half / std::tan(half)) / (t * t);
}
long double c_prime_over_t_closed(long double t) {
  const long double half = t / 2;
  const long double h = half / std::tan(half), q = half / std::sin(half);
  return (h + q * q - 2.0L) / (t * t * t * t);
}

/// The leading terms of c(t) = sum_k |B_{2k+2}| / (2k+2)! t^{2k} and of c'(t)/t, differentiated term
/// by term from them.
double c_series(double t) {
  const double s = t * t;
  return 1.0 / 12 + s / 720 + s * s / 30240 + s * s * s / 1209600 + s * s * s * s / 47900160;
}
double c_prime_over_t_series(double t) {
  const double s = t * t;
  return 2.0 / 720 + 4.0 * s / 30240 + 6.0 * s * s / 1209600 + 8.0 * s * s * s / 47900160;
}

TEST(Quadrotor, CoefficientOfRDotMatchesItsSeriesNearZero) {
  // Truncation of c_series: the next term t^10 691/1307674368000 is < 1e-22 at t = 0.05; that of
  // c_prime_over_t_series, 10 t^8 691/1307674368000, is < 1e-16 relative at t = 0.1.
  const Quadrotor quad;
  for (double t : {1e-150, 1e-8, 1e-4, 1e-3, 1e-2, 0.03, 0.05}) {
    const CCoefficients k = read_c(quad, t);
    EXPECT_NEAR(k.c, c_series(t), 4.0 * kEps * c_series(t)) << "t = " << t;
  }
  for (double t : {1e-3, 1e-2, 0.03, 0.1}) {
    const CCoefficients k = read_c(quad, t);
    // The read-back loses eps c / t^2 absolute (2 c cancels): tolerance 8 eps / (12 t^2).
    EXPECT_NEAR(k.c_prime_over_t, c_prime_over_t_series(t), 8.0 * kEps / (12.0 * t * t)) << "t = " << t;
  }
  // The leading coefficients themselves, by the limits (c - 1/12) / t^2 -> 1/720 and c'/t -> 1/360.
  EXPECT_NEAR((read_c(quad, 1e-3).c - 1.0 / 12) / 1e-6, 1.0 / 720, 1e-8);
  EXPECT_NEAR(read_c(quad, 0.02).c_prime_over_t, 1.0 / 360, 1e-6);
}

TEST(Quadrotor, CoefficientOfRDotMatchesLongDoubleClosedFormOnBothSidesOfTheSwitch) {
  const Quadrotor quad;
  std::vector<double> ts = {0.05, 0.1, 0.3, 0.5, 0.7, 0.9, 1.2, 1.6, 2.0, 2.5, 3.0, 4.0, 5.0};
  for (double delta : {-1e-3, -1e-9, -1e-15, 0.0, 1e-15, 1e-9, 1e-3})
    ts.push_back(kSeriesSwitch * (1.0 + delta));
  for (double t : ts) {
    const CCoefficients k = read_c(quad, t);
    const double c_ref = static_cast<double>(c_closed(t));
    // Series branch: a few ulp. Closed form (t >= 1): its cancellation, measured at 2e-15 at t = 1.
    EXPECT_NEAR(k.c, c_ref, 5e-15 * c_ref) << "t = " << t;
    if (t >= 0.5) {
      const double cp_ref = static_cast<double>(c_prime_over_t_closed(t));
      // Read-back error ~ 4 eps c / t^2 absolute; the closed form's own cancellation ~ eps / t^4
      // relative (2e-13 at t = 1), harmless as c'/t only enters the Jacobian times t^3 |w|.
      const double tol = 8.0 * kEps * k.c / (t * t) + 5e-13 * cp_ref;
      EXPECT_NEAR(k.c_prime_over_t, cp_ref, tol) << "t = " << t;
    }
  }
}

TEST(Quadrotor, MatchesAnIndependentTransliterationOfTheEquations) {
  // The model written out directly: AngleAxis for R, long-double closed form for c, J = inertia I
  // with the gyroscopic term kept (it vanishes for isotropic J).
  const Quadrotor quad(QuadrotorParameters::real_world());
  const QuadrotorParameters p = quad.physical();
  for (unsigned seed = 0; seed < 20; ++seed) {
    const Vector x = random_state(seed);
    const Vector u = random_controls(quad, seed);
    const Vec3 v = x.segment<3>(kV), r = x.segment<3>(kR), w = x.segment<3>(kW);
    const double t = r.norm();
    const double c = t < 0.05 ? c_series(t) : static_cast<double>(c_closed(t));
    const Mat3 J = p.inertia * Mat3::Identity();
    const Vec3 torque(p.rho * (u(1) - u(3)), p.rho * (u(2) - u(0)), p.km * (u(0) - u(1) + u(2) - u(3)));
    Vector expected(12);
    expected << v, -p.gravity * Vec3::UnitZ() + (u.sum() * rotation(r).col(2) - p.kv * v) / p.mass,
        w + 0.5 * hat(r) * w + c * hat(r) * hat(r) * w, J.inverse() * (torque - hat(w) * J * w);
    EXPECT_TRUE(test::matrices_near(quad.f(x, u), expected, 1e-13, 1e-14)) << "seed " << seed;
  }
}

TEST(Quadrotor, NamedStatesControlsAndParametersFollowTheFixedConvention) {
  const Quadrotor quad(QuadrotorParameters::real_world());
  EXPECT_EQ(quad.name(), "quadrotor");
  ASSERT_EQ(quad.state_dim(), 12);
  ASSERT_EQ(quad.control_dim(), 4);
  EXPECT_EQ(names_of(quad.states()), (std::vector<std::string>{"px", "py", "pz", "vx", "vy", "vz", "rx",
                                                                "ry", "rz", "wx", "wy", "wz"}));
  EXPECT_EQ(names_of(quad.controls()), (std::vector<std::string>{"u1", "u2", "u3", "u4"}));
  const std::vector<std::string> units = {"m",   "m",   "m",   "m/s",   "m/s",   "m/s",
                                          "rad", "rad", "rad", "rad/s", "rad/s", "rad/s"};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(quad.states()[static_cast<std::size_t>(i)].unit, units[i]);
  for (const Quantity& q : quad.controls()) EXPECT_EQ(q.unit, "N");

  const auto params = quad.parameters();
  ASSERT_EQ(params.size(), 6u);
  const std::vector<std::string> names = {"mass", "kv", "km", "inertia", "rho", "gravity"};
  const std::vector<std::string> param_units = {"kg", "N s/m", "m", "kg m^2", "m", "m/s^2"};
  const std::vector<double> values = {0.7, 0.15, 0.025, 0.05, 0.17, 9.81};
  for (std::size_t i = 0; i < params.size(); ++i) {
    EXPECT_EQ(params[i].name, names[i]);
    EXPECT_EQ(params[i].unit, param_units[i]);
    EXPECT_DOUBLE_EQ(params[i].value, values[i]);
  }
}

TEST(Quadrotor, PresetsAreThePapersAppendix) {
  const auto sim = QuadrotorParameters::simulator(), real = QuadrotorParameters::real_world();
  EXPECT_DOUBLE_EQ(sim.mass, 0.5);
  EXPECT_DOUBLE_EQ(real.mass, 0.7);  // "40% heavier"
  for (const auto& p : {sim, real}) {
    EXPECT_DOUBLE_EQ(p.kv, 0.15);
    EXPECT_DOUBLE_EQ(p.km, 0.025);
    EXPECT_DOUBLE_EQ(p.inertia, 0.05);
    EXPECT_DOUBLE_EQ(p.rho, 0.17);
    EXPECT_DOUBLE_EQ(p.gravity, 9.81);
  }
}

TEST(Quadrotor, RejectsInvalidParametersNamingThemAndTheirValue) {
  auto expect_rejected = [](QuadrotorParameters p, const std::string& name, const std::string& value) {
    try {
      Quadrotor bad(p);
      ADD_FAILURE() << "expected std::invalid_argument for " << name;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'" + name + "'"), std::string::npos) << what;
      EXPECT_NE(what.find(value), std::string::npos) << what;
    }
  };
  const QuadrotorParameters ok;
  auto with = [&](auto member, double value) {
    QuadrotorParameters p = ok;
    p.*member = value;
    return p;
  };
  expect_rejected(with(&QuadrotorParameters::mass, 0.0), "mass", "0");
  expect_rejected(with(&QuadrotorParameters::mass, -0.5), "mass", "-0.5");
  expect_rejected(with(&QuadrotorParameters::mass, std::nan("")), "mass", "nan");
  expect_rejected(with(&QuadrotorParameters::inertia, -0.05), "inertia", "-0.05");
  expect_rejected(with(&QuadrotorParameters::rho, 0.0), "rho", "0");
  expect_rejected(with(&QuadrotorParameters::kv, -0.1), "kv", "-0.1");
  expect_rejected(with(&QuadrotorParameters::km, -0.025), "km", "-0.025");
  expect_rejected(with(&QuadrotorParameters::km, std::numeric_limits<double>::infinity()), "km", "inf");
  expect_rejected(with(&QuadrotorParameters::gravity, 0.0), "gravity", "0");
  // No drag and no yaw torque are physically meaningful.
  EXPECT_NO_THROW(Quadrotor(with(&QuadrotorParameters::kv, 0.0)));
  EXPECT_NO_THROW(Quadrotor(with(&QuadrotorParameters::km, 0.0)));
}

}  // namespace
}  // namespace gpilqg
