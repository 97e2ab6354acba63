// The finite-difference wrappers for black-box simulators, checked against the analytic Jacobians
// of the built-in systems (an independent computation of the same derivatives).

#include <gtest/gtest.h>

#include "gpilqg/core/cartpole.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

TEST(FiniteDifference, CentralDifferenceIsExactForAQuadraticUpToRoundOff) {
  // g(z) = [z0^2 + 3 z0 z1, -z1^2]: its central difference has no truncation error.
  const VectorFunction g = [](const Vector& z, Vector& out) {
    out(0) = z(0) * z(0) + 3.0 * z(0) * z(1);
    out(1) = -z(1) * z(1);
  };
  Vector z(2);
  z << 1.7, -250.0;
  Matrix expected(2, 2);
  expected << 2 * 1.7 + 3 * -250.0, 3 * 1.7, 0.0, 500.0;
  // Round-off: eps |g| / h with |g| ~ 6e4 and h = 6e-6 * 250 -> ~1e-8.
  EXPECT_TRUE(test::matrices_near(central_difference_jacobian(g, z, 2), expected, 1e-7, 1e-9));
}

TEST(FiniteDifference, BlackBoxDynamicsMatchTheAnalyticCartPole) {
  auto analytic = std::make_shared<CartPole>(CartPoleParameters::real_world());
  FiniteDifferenceDynamics black_box(
      "cartpole_black_box", analytic->states(), analytic->controls(), analytic->parameters(),
      [analytic](const Vector& x, const Vector& u, Vector& xdot) { analytic->evaluate(x, u, xdot); });
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Vector x = test::random_vector(4, -3.0, 3.0, seed);
    const Vector u = test::random_vector(1, -5.0, 5.0, seed + 7);
    DynamicsJacobians numeric, exact;
    Vector a(4), b(4);
    black_box.evaluate(x, u, a, &numeric);
    analytic->evaluate(x, u, b, &exact);
    EXPECT_MATRIX_NEAR(a, b, 0.0);
    EXPECT_TRUE(test::matrices_near(numeric.fx, exact.fx, 1e-7, 1e-7)) << "seed " << seed;
    EXPECT_TRUE(test::matrices_near(numeric.fu, exact.fu, 1e-7, 1e-7)) << "seed " << seed;
  }
}

TEST(FiniteDifference, BlackBoxDynamicsDriveTheIntegratorsAndTheNoiseModel) {
  // A black box plugs in wherever an analytic system does: RK4 Jacobians and noise columns agree.
  auto analytic = std::make_shared<CartPole>();
  auto black_box = std::make_shared<FiniteDifferenceDynamics>(
      "bb", analytic->states(), analytic->controls(), analytic->parameters(),
      [analytic](const Vector& x, const Vector& u, Vector& xdot) { analytic->evaluate(x, u, xdot); });
  IntegratedStepModel exact(analytic, Integrator::RK4, 0.05), numeric(black_box, Integrator::RK4, 0.05);
  const Vector x = test::random_vector(4, -1.0, 1.0, 3), u = Vector::Constant(1, 2.0);
  StepJacobians je, jn;
  Vector a(4), b(4);
  exact.step(x, u, a, &je);
  numeric.step(x, u, b, &jn);
  EXPECT_MATRIX_NEAR(a, b, 0.0);
  EXPECT_TRUE(test::matrices_near(jn.A, je.A, 1e-8, 1e-8));
  EXPECT_TRUE(test::matrices_near(jn.B, je.B, 1e-8, 1e-8));
}

TEST(FiniteDifference, DiscreteBlackBoxMatchesTheAnalyticStep) {
  auto quad = make_system("quadrotor", Preset::RealWorld);
  auto rk4 = std::make_shared<IntegratedStepModel>(quad, Integrator::RK4, 0.02);
  FiniteDifferenceStepModel black_box(12, 4, 0.02, [rk4](const Vector& x, const Vector& u, Vector& next) {
    rk4->step(x, u, next);
  });
  EXPECT_EQ(black_box.state_dim(), 12);
  EXPECT_EQ(black_box.control_dim(), 4);
  EXPECT_DOUBLE_EQ(black_box.dt(), 0.02);
  const Vector x = test::random_vector(12, -1.0, 1.0, 21), u = test::random_vector(4, 0.5, 2.0, 22);
  StepJacobians je, jn;
  Vector a(12), b(12);
  rk4->step(x, u, a, &je);
  black_box.step(x, u, b, &jn);
  EXPECT_MATRIX_NEAR(a, b, 0.0);
  EXPECT_TRUE(test::matrices_near(jn.A, je.A, 1e-8, 1e-8));
  EXPECT_TRUE(test::matrices_near(jn.B, je.B, 1e-8, 1e-8));
}

TEST(FiniteDifference, RejectsAMissingSimulatorOrABadStep) {
  EXPECT_THROW(FiniteDifferenceDynamics("x", {{"a", "-"}}, {}, {}, nullptr), std::invalid_argument);
  EXPECT_THROW(FiniteDifferenceStepModel(2, 1, 0.1, nullptr), std::invalid_argument);
  EXPECT_THROW(FiniteDifferenceStepModel(
                   2, 1, 0.1, [](const Vector&, const Vector&, Vector&) {}, -1.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
