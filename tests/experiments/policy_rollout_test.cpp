/// roll_out_policy (policy_rollout.hpp), the rollouts of `gpilqg rollout`: what the log holds, the task
/// costs, and the episodes that diverge at their first step.

#include <gtest/gtest.h>

#include <stdexcept>

#include "gpilqg/control/trajectory.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/policy_rollout.hpp"

namespace gpilqg {
namespace {

constexpr double kDt = 0.05;
constexpr int kHorizon = 20;

/// An open-loop cart-pole policy: u = 1 N at every step (K = 0, k = 0).
PolicyFile constant_force_policy() {
  PolicyFile file;
  file.dt = kDt;
  file.policy.x_bar = Matrix::Zero(4, kHorizon + 1);
  file.policy.u_bar = Matrix::Constant(1, kHorizon, 1.0);
  file.policy.k = Matrix::Zero(1, kHorizon);
  file.policy.K.assign(kHorizon, Matrix::Zero(1, 4));
  return file;
}

struct CartpoleWorld {
  std::shared_ptr<const StepModel> step = make_step_model(make_system("cartpole"), Integrator::RK4, kDt, 10);
};

TEST(PolicyRollout, NoiseFreeEpisodesLogTheMeasuredStatesAndTheAppliedControls) {
  const PolicyFile policy = constant_force_policy();
  const CartpoleWorld world;
  const Vector x0 = Vector::Zero(4);
  const QuadraticCost cost(kDt, Matrix::Zero(4, 4), Matrix::Identity(1, 1), Matrix::Identity(4, 4), Vector::Zero(4));
  PolicyRolloutRequest request;
  request.policy = &policy;
  request.world = world.step.get();
  request.system = system_signature("cartpole");
  request.x0 = x0;
  request.episodes = 2;
  request.task_cost = &cost;

  const PolicyRolloutResult result = roll_out_policy(request);
  EXPECT_EQ(result.diverged, 0);
  EXPECT_EQ(result.dropped, 0);
  EXPECT_EQ(result.overflowed, 0);
  EXPECT_EQ(result.log.system.name, "cartpole");
  ASSERT_EQ(result.log.episodes.size(), 2u);
  for (int r = 0; r < 2; ++r) {
    const Episode& e = result.log.episodes[static_cast<std::size_t>(r)];
    EXPECT_EQ(e.id, r);
    ASSERT_EQ(e.t.size(), kHorizon + 1);
    EXPECT_DOUBLE_EQ(e.t(kHorizon), kDt * kHorizon);
    EXPECT_TRUE(e.x.row(0).transpose() == x0);
    // Every row holds the applied control; the last repeats it (no transition starts there).
    EXPECT_TRUE((e.u.array() == 1.0).all());
  }
  // Without noise every episode is the same, and its task cost is that of its trajectory.
  EXPECT_TRUE(result.log.episodes[0].x == result.log.episodes[1].x);
  Trajectory truth;
  truth.x = result.log.episodes[0].x.transpose();
  truth.u = result.log.episodes[0].u.topRows(kHorizon).transpose();
  ASSERT_EQ(result.costs.size(), 2u);
  EXPECT_EQ(result.costs[0], trajectory_cost(cost, truth));
  EXPECT_EQ(result.costs[1], result.costs[0]);
}

TEST(PolicyRollout, EpisodesDivergingAtTheirFirstStepAreCountedAndLeftOut) {
  const PolicyFile policy = constant_force_policy();
  const CartpoleWorld world;
  PolicyRolloutRequest request;
  request.policy = &policy;
  request.world = world.step.get();
  request.system = system_signature("cartpole");
  request.x0 = Vector::Zero(4);
  request.x0(3) = 1e5;  // a pole spinning so fast that the first step leaves the divergence bound
  request.episodes = 3;

  const PolicyRolloutResult result = roll_out_policy(request);
  EXPECT_TRUE(result.log.episodes.empty());
  EXPECT_EQ(result.dropped, 3);
  EXPECT_EQ(result.diverged, 3);
  EXPECT_TRUE(result.costs.empty());
}

TEST(PolicyRollout, RefusesARequestWithoutPolicyOrWorldOrWithAWrongInitialState) {
  const PolicyFile policy = constant_force_policy();
  const CartpoleWorld world;
  PolicyRolloutRequest request;
  request.x0 = Vector::Zero(4);
  EXPECT_THROW(roll_out_policy(request), std::invalid_argument);
  request.policy = &policy;
  EXPECT_THROW(roll_out_policy(request), std::invalid_argument);
  request.world = world.step.get();
  request.x0 = Vector::Zero(3);
  EXPECT_THROW(roll_out_policy(request), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
