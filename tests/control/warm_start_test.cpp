// The warm start of a solve on a changed model (control/warm_start.hpp), on a linearised inverted
// pendulum held off upright that turns out 30% longer (the cart-pole's real pole in miniature): the
// previous optimum's controls open loop fall away from x_bar; its policy in closed loop does not. The
// closed-loop controls are checked against a hand-written loop of the same recursion.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/control/warm_start.hpp"
#include "linear_models.hpp"

namespace gpilqg {
namespace {

constexpr double kDt = 0.05;
constexpr int kT = 60;

/// x = (angle, rate): angle'' = (g / l) angle + u (an inverted pendulum of length l linearised
/// upright, per unit inertia), Euler.
Matrix pendulum_A(double length) {
  Matrix A(2, 2);
  A << 1.0, kDt, 9.81 / length * kDt, 1.0;
  return A;
}
Matrix pendulum_B() { return (Matrix(2, 1) << 0.0, kDt).finished(); }
test::LinearStepModel pendulum(double length) { return test::LinearStepModel(pendulum_A(length), pendulum_B(), kDt); }

struct PendulumPair {
  test::LinearStepModel planned = pendulum(1.0);
  test::LinearStepModel changed = pendulum(1.3);
  QuadraticCost cost{kDt, Vector::Constant(2, 10.0).asDiagonal(), Matrix::Identity(1, 1) * 0.01,
                     Vector::Constant(2, 100.0).asDiagonal(), (Vector(2) << 0.3, 0.0).finished()};
  Vector x0 = Vector::Zero(2);

  /// The optimum on the planned model: what the previous round hands over.
  AffinePolicy previous() const {
    DdpProblem p;
    p.model = &planned;
    p.cost = &cost;
    p.x0 = x0;
    p.horizon = kT;
    DdpOptions o;
    o.variant = DdpVariant::ILQR;
    return DdpSolver(o).solve(p, Matrix::Zero(1, kT)).policy;
  }
};

/// The closed loop written out for a linear model: u_t = u_bar_t + k_t + K_t (x_t - x_bar_t), x' = A x + B u.
Matrix closed_loop_by_hand(const Matrix& A, const Matrix& B, const AffinePolicy& policy, Vector x) {
  Matrix u(policy.u_bar.rows(), policy.horizon());
  for (int t = 0; t < policy.horizon(); ++t) {
    u.col(t) = policy.u_bar.col(t) + policy.k.col(t) + policy.K[static_cast<std::size_t>(t)] * (x - policy.x_bar.col(t));
    x = A * x + B * u.col(t);
  }
  return u;
}

double cost_of(const StepModel& model, const Cost& cost, const Vector& x0, const Matrix& u) {
  const RolloutResult r = rollout(model, x0, u);
  return r.finite ? trajectory_cost(cost, r.trajectory) : std::numeric_limits<double>::infinity();
}

TEST(WarmStart, OnTheModelItWasPlannedOnThePolicyReplaysItsOwnControls) {
  const PendulumPair s;
  const AffinePolicy previous = s.previous();
  const WarmStartControls w = warm_start_controls(s.planned, s.cost, previous, s.x0);
  EXPECT_EQ(w.kind, WarmStart::ClosedLoop);
  EXPECT_LT((w.controls - previous.u_bar).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(w.cost, w.other_cost, 1e-9 * w.cost);
}

TEST(WarmStart, OnAChangedUnstableModelTheClosedLoopStaysNearTheOptimum) {
  const PendulumPair s;
  const AffinePolicy previous = s.previous();
  const WarmStartControls w = warm_start_controls(s.changed, s.cost, previous, s.x0);
  ASSERT_EQ(w.kind, WarmStart::ClosedLoop);
  EXPECT_LT((w.controls - closed_loop_by_hand(pendulum_A(1.3), pendulum_B(), previous, s.x0)).cwiseAbs().maxCoeff(), 1e-9);
  // Its cost is that of replaying the chosen controls, and the open loop's that of u_bar.
  EXPECT_NEAR(w.cost, cost_of(s.changed, s.cost, s.x0, w.controls), 1e-9 * w.cost);
  EXPECT_NEAR(w.other_cost, cost_of(s.changed, s.cost, s.x0, previous.u_bar), 1e-9 * w.other_cost);
  // The optimum on the planned model, its open loop on the changed model, and the closed loop there.
  const double optimum = cost_of(s.planned, s.cost, s.x0, previous.u_bar);
  EXPECT_GT(w.other_cost, 10.0 * optimum);  // open loop: the pendulum falls
  EXPECT_LT(w.cost, 2.0 * optimum);         // closed loop: it does not
  // And the changed model's own optimum is near the closed loop, far from the open loop.
  DdpProblem p;
  p.model = &s.changed;
  p.cost = &s.cost;
  p.x0 = s.x0;
  p.horizon = kT;
  DdpOptions o;
  o.variant = DdpVariant::ILQR;
  const double new_optimum = DdpSolver(o).solve(p, w.controls).nominal_cost;
  EXPECT_LT(w.cost - new_optimum, 0.1 * (w.other_cost - new_optimum));
}

TEST(WarmStart, HarmfulFeedbackLosesToTheOpenLoop) {
  const PendulumPair s;
  AffinePolicy previous = s.previous();
  for (Matrix& gain : previous.K) gain = -gain;  // pushes away from x_bar (on the planned model x = x_bar)
  const WarmStartControls w = warm_start_controls(s.changed, s.cost, previous, s.x0);
  EXPECT_EQ(w.kind, WarmStart::OpenLoop);
  EXPECT_EQ(w.controls, previous.u_bar);
  EXPECT_NEAR(w.cost, cost_of(s.changed, s.cost, s.x0, previous.u_bar), 1e-9 * w.cost);
  EXPECT_GT(w.other_cost, w.cost);
}

TEST(WarmStart, WhenBothDivergeTheNominalControlsAreReturned) {
  const PendulumPair s;
  AffinePolicy previous = s.previous();
  previous.u_bar.setConstant(1e14);  // both rollouts pass the divergence bound of rollout.hpp
  for (Matrix& gain : previous.K) gain.setConstant(1e14);
  const WarmStartControls w = warm_start_controls(s.changed, s.cost, previous, s.x0);
  EXPECT_EQ(w.kind, WarmStart::OpenLoop);
  EXPECT_EQ(w.controls, previous.u_bar);
  EXPECT_TRUE(std::isinf(w.cost));
  EXPECT_TRUE(std::isinf(w.other_cost));
}

TEST(WarmStart, APolicyOfOtherSizesIsRefused) {
  const PendulumPair s;
  AffinePolicy previous = s.previous();
  previous.K.pop_back();
  EXPECT_THROW(warm_start_controls(s.changed, s.cost, previous, s.x0), std::invalid_argument);
  EXPECT_THROW(warm_start_controls(s.changed, s.cost, s.previous(), Vector::Zero(3)), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
