// The physical-effects library and the "system + effects" decorator: analytic Jacobians against
// central differences, the generalised-force map against independent physics (energy balance,
// hover), and the model description (adding, recalibrating, naming errors).

#include <gtest/gtest.h>

#include <cmath>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/effects.hpp"
#include "gpilqg/core/quadrotor.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// The model with every force of the library at a nonzero value and a gain of 1.2.
ModelSpec everything(const std::string& system) {
  ModelSpec spec;
  spec.system = system;
  double value = 0.3;
  for (const LibraryEffect& e : effect_library(system)) {
    if (e.kind == EffectKind::Force) spec = spec.with(e, Vector::Constant(1, value));
    value += 0.1;
  }
  return spec.with(find_effect(system, "actuator_gain"), Vector::Constant(1, 1.2));
}

void expect_jacobians_match_central_differences(const Dynamics& model, double x_range, double u_lo, double u_hi) {
  const int n = model.state_dim(), m = model.control_dim();
  for (unsigned seed = 1; seed <= 20; ++seed) {
    // Velocities spread over +-x_range so that the tanh of Coulomb friction is sampled on its
    // steep part (|v| < 0.05) as well as on its flat part.
    const Vector x = test::random_vector(n, -x_range, x_range, seed) * (seed % 2 == 0 ? 0.02 : 1.0);
    const Vector u = test::random_vector(m, u_lo, u_hi, 100 + seed);
    DynamicsJacobians jac;
    Vector xdot(n);
    model.evaluate(x, u, xdot, &jac);
    EXPECT_TRUE(test::matrices_near(xdot, model.f(x, u), 0.0)) << "f with and without Jacobians";
    const Matrix fx = test::numeric_jacobian([&](const Vector& xs) { return model.f(xs, u); }, x, test::kFdStep);
    const Matrix fu = test::numeric_jacobian([&](const Vector& us) { return model.f(x, us); }, u, test::kFdStep);
    EXPECT_TRUE(test::matrices_near(jac.fx, fx, 2e-6, 1e-6)) << "seed " << seed;
    EXPECT_TRUE(test::matrices_near(jac.fu, fu, 2e-6, 1e-6)) << "seed " << seed;
  }
}

TEST(Effects, CartPoleJacobiansMatchCentralDifferences) {
  expect_jacobians_match_central_differences(*everything("cartpole").build(), 2.0, -10.0, 10.0);
}

TEST(Effects, QuadrotorJacobiansMatchCentralDifferences) {
  expect_jacobians_match_central_differences(*everything("quadrotor").build(), 1.0, 0.5, 2.0);
}

TEST(Effects, InputMatrixMatchesTheGenericCentralDifferences) {
  for (const std::string system : {"cartpole", "quadrotor"}) {
    const DynamicsPtr model = everything(system).build();
    const Vector x = test::random_vector(model->state_dim(), -1.0, 1.0, 7);
    const Vector u = test::random_vector(model->control_dim(), 0.5, 2.0, 8);
    InputMatrix analytic, numeric;
    model->input_matrix(x, u, analytic);
    model->Dynamics::input_matrix(x, u, numeric);  // the base class differentiates fu numerically
    EXPECT_TRUE(test::matrices_near(analytic.b, numeric.b, 1e-12, 1e-12)) << system;
    for (std::size_t j = 0; j < analytic.d_dx.size(); ++j) {
      EXPECT_TRUE(test::matrices_near(analytic.d_dx[j], numeric.d_dx[j], 1e-6, 1e-6)) << system << " column " << j;
      EXPECT_TRUE(test::matrices_near(analytic.d_du[j], numeric.d_du[j], 1e-6, 1e-6)) << system << " column " << j;
    }
  }
}

TEST(Effects, CartPoleForceMapDerivativeMatchesCentralDifferences) {
  const CartPole cp;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Vector x = test::random_vector(4, -3.0, 3.0, seed);
    Matrix W;
    std::vector<Matrix> dW;
    cp.generalised_force_map(x, W, &dW);
    for (int j = 0; j < 4; ++j) {
      const Matrix numeric = test::numeric_jacobian(
          [&](const Vector& xs) {
            Matrix Ws;
            cp.generalised_force_map(xs, Ws, nullptr);
            return Vector(Ws.reshaped());
          },
          x, test::kFdStep);
      EXPECT_TRUE(test::matrices_near(Matrix(dW[static_cast<std::size_t>(j)].reshaped()), numeric.col(j), 1e-8, 1e-7));
    }
  }
}

/// Energy balance, an independent check of W: dE/dt along the decorated dynamics equals the power of
/// the non-conservative forces, (k u + Q_x) x_dot + Q_theta theta_dot.
TEST(Effects, CartPoleEnergyBalanceWithFrictionGainAndForce) {
  const CartPole cp;
  ModelSpec spec = everything("cartpole");
  const DynamicsPtr model = spec.build();
  const double b = spec.current_values(find_effect("cartpole", "cart_viscous_friction"))(0);
  const double mu = spec.current_values(find_effect("cartpole", "cart_coulomb_friction"))(0);
  const double c = spec.current_values(find_effect("cartpole", "pole_viscous_damping"))(0);
  const double tau = spec.current_values(find_effect("cartpole", "pole_coulomb_friction"))(0);
  const double F = spec.current_values(find_effect("cartpole", "external_force_x"))(0);
  const double cd = spec.current_values(find_effect("cartpole", "quadratic_drag"))(0);
  const double Fx = spec.current_values(find_effect("cartpole", "constant_force:x"))(0);
  const double Ft = spec.current_values(find_effect("cartpole", "constant_force:theta"))(0);
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Vector x = test::random_vector(4, -2.0, 2.0, seed);
    const Vector u = test::random_vector(1, -5.0, 5.0, 50 + seed);
    const Matrix grad_e = test::numeric_jacobian([&](const Vector& xs) { return Vector::Constant(1, cp.energy(xs)); }, x, test::kFdStep);
    const double dE_dt = (grad_e * model->f(x, u))(0);
    const double Qx = -b * x(1) - mu * std::tanh(x(1) / 0.05) + F - cd * std::abs(x(1)) * x(1) + Fx;
    const double Qt = -c * x(3) - tau * std::tanh(x(3) / 0.05) + Ft;
    const double power = (1.2 * u(0) + Qx) * x(1) + Qt * x(3);
    EXPECT_NEAR(dE_dt, power, 1e-6 * (1.0 + std::abs(power))) << "seed " << seed;
  }
}

TEST(Effects, QuadrotorHoversOnAnUpwardExternalForce) {
  ModelSpec spec;
  spec.system = "quadrotor";
  spec = spec.with(find_effect("quadrotor", "external_force_z"), Vector::Constant(1, 0.5 * 9.81));
  const Vector f = spec.build()->f(Vector::Zero(12), Vector::Zero(4));
  EXPECT_TRUE(test::matrices_near(f, Vector::Zero(12), 1e-14));
  // Quadratic drag along x only: v_dot_x = -(kv v + c_d v^2) / m.
  ModelSpec drag;
  drag.system = "quadrotor";
  drag = drag.with(find_effect("quadrotor", "quadratic_drag"), Vector::Constant(1, 0.2));
  Vector x = Vector::Zero(12);
  x(3) = 2.0;
  const Quadrotor q;
  const Vector u = Vector::Constant(4, q.hover_force());
  EXPECT_NEAR(drag.build()->f(x, u)(3), -(0.15 * 2.0 + 0.2 * 4.0) / 0.5, 1e-12);
}

TEST(Effects, GainAndRecalibrationAreTheSystemWithOtherNumbers) {
  ModelSpec spec;
  const Vector x = test::random_vector(4, -1.0, 1.0, 3), u = Vector::Constant(1, 2.0);
  const DynamicsPtr base = spec.build();
  const DynamicsPtr gained = spec.with(find_effect("cartpole", "actuator_gain"), Vector::Constant(1, 1.5)).build();
  EXPECT_TRUE(test::matrices_near(gained->f(x, u), base->f(x, 1.5 * u), 1e-15));
  const ModelSpec longer = spec.with(find_effect("cartpole", "param:pole_length"), Vector::Constant(1, 1.3));
  EXPECT_TRUE(test::matrices_near(longer.build()->f(x, u), make_system("cartpole", Preset::RealWorld)->f(x, u), 0.0));
  EXPECT_DOUBLE_EQ(longer.current_values(find_effect("cartpole", "param:pole_length"))(0), 1.3);
  EXPECT_DOUBLE_EQ(spec.current_values(find_effect("cartpole", "param:pole_length"))(0), 1.0);
  EXPECT_DOUBLE_EQ(spec.current_values(find_effect("cartpole", "cart_viscous_friction"))(0), 0.0);
  EXPECT_EQ(longer.describe(), (std::vector<std::string>{"param:pole_length: pole_length = 1.3 m"}));
  // Adding at the current values leaves the model unchanged; a force is replaced, not stacked.
  const LibraryEffect& b = find_effect("cartpole", "cart_viscous_friction");
  const ModelSpec twice = spec.with(b, Vector::Constant(1, 0.4)).with(b, Vector::Constant(1, 0.7));
  ASSERT_EQ(twice.forces.size(), 1u);
  EXPECT_DOUBLE_EQ(twice.forces[0].second(0), 0.7);
}

TEST(Effects, LibraryHoldsTheFixedNames) {
  auto names = [](const std::string& system) {
    std::vector<std::string> out;
    for (const auto& e : effect_library(system)) out.push_back(e.name);
    return out;
  };
  EXPECT_EQ(names("cartpole"), (std::vector<std::string>{"cart_viscous_friction", "cart_coulomb_friction",
                                                         "pole_viscous_damping", "pole_coulomb_friction",
                                                         "external_force_x", "quadratic_drag", "actuator_gain",
                                                         "input_delay", "param:cart_mass", "param:pole_mass",
                                                         "param:pole_length", "constant_force:x",
                                                         "constant_force:theta"}));
  EXPECT_EQ(names("quadrotor"), (std::vector<std::string>{"external_force_x", "external_force_y", "external_force_z",
                                                          "quadratic_drag", "actuator_gain", "input_delay", "param:mass",
                                                          "param:kv", "param:km", "param:inertia", "param:rho",
                                                          "constant_force:px", "constant_force:py", "constant_force:pz",
                                                          "constant_force:rx", "constant_force:ry", "constant_force:rz"}));
}

TEST(Effects, BadInputNamesTheProblemAndTheChoices) {
  try {
    find_effect("cartpole", "external_force_y");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'external_force_y'"), std::string::npos) << what;
    EXPECT_NE(what.find("cart_viscous_friction, cart_coulomb_friction"), std::string::npos) << what;
  }
  ModelSpec spec;
  EXPECT_THROW(spec.with(find_effect("cartpole", "param:cart_mass"), Vector::Constant(1, -1.0)), std::invalid_argument);
  EXPECT_THROW(spec.with(find_effect("cartpole", "cart_viscous_friction"), Vector::Constant(1, NAN)), std::invalid_argument);
  EXPECT_THROW(spec.with(find_effect("cartpole", "cart_viscous_friction"), Vector::Zero(2)), std::invalid_argument);
  EXPECT_THROW(EffectDynamics(make_system("cartpole"), 1.0, {{find_effect("cartpole", "quadratic_drag").force, Vector()}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
