#include "gpilqg/experiments/policy_rollout.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gpilqg/control/trajectory.hpp"
#include "gpilqg/experiments/run_setup.hpp"
#include "gpilqg/experiments/task_actions.hpp"

namespace gpilqg {

namespace {

/// One episode of the log: the measured states (what the controller saw) and the applied controls,
/// one row per step up to the last finite state; the last row repeats the last control (no transition
/// starts there).
Episode episode_of(const RealRollout& r, int id, double dt) {
  const int rows = r.steps_completed + 1;
  Episode e;
  e.id = id;
  e.t.resize(rows);
  for (int j = 0; j < rows; ++j) e.t(j) = dt * j;
  e.x = r.measured.leftCols(rows).transpose();
  e.u.resize(rows, r.truth.u.rows());
  e.u.topRows(rows - 1) = r.truth.u.leftCols(rows - 1).transpose();
  e.u.row(rows - 1) = e.u.row(std::max(0, rows - 2));
  return e;
}

}  // namespace

PolicyRolloutResult roll_out_policy(const PolicyRolloutRequest& request) {
  if (request.policy == nullptr || request.world == nullptr)
    throw std::invalid_argument("roll_out_policy: the request needs a policy and a world");
  const PolicyFile& policy = *request.policy;
  const AffinePolicy& law = policy.policy;
  if (request.x0.size() != law.x_bar.rows())
    throw std::invalid_argument("roll_out_policy: x0 has " + std::to_string(request.x0.size()) + " values; the policy " +
                                std::to_string(law.x_bar.rows()) + " states");

  WorldRollout setup;
  setup.world = request.world;
  setup.x0 = request.x0;
  setup.horizon = law.horizon();
  setup.exploration_std = request.exploration_std;
  setup.observation_std = request.observation_std;
  setup.u_min = law.u_min;
  setup.u_max = law.u_max;
  const Controller act = [&law](int t, const VectorCRef& x, VectorRef u) { law.control(t, x, u); };

  PolicyRolloutResult result;
  result.log.system = request.system;
  for (int r = 0; r < request.episodes; ++r) {
    auto rng = data_rollout_rng(request.seed, 0, "gp_ilqg", policy.round, r);
    const RealRollout rollout = roll_out(setup, act, rng);
    if (!rollout.finite) ++result.diverged;
    if (request.task_cost != nullptr && rollout.finite) {
      const double value = trajectory_cost(*request.task_cost, rollout.truth);
      if (std::isfinite(value)) result.costs.push_back(value);
      else ++result.overflowed;  // states within the divergence bound, the weighted sum beyond a double
    }
    if (rollout.steps_completed == 0) {
      ++result.dropped;
      continue;
    }
    result.log.episodes.push_back(episode_of(rollout, r, policy.dt));
  }
  return result;
}

}  // namespace gpilqg
