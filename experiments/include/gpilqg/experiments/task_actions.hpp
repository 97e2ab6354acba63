#pragma once
/// @file task_actions.hpp
/// The three things every algorithm of `gpilqg run` does on a task, written once:
///
///  - plan: a finite-horizon DDP solve on some model (iLQG on the world or the simulator, Robust-iLQG
///    on the GP-corrected simulator, DDP over the belief for PDDP) gives a Plan: nominal trajectory,
///    affine feedback policy, the predicted cost and the solve time;
///  - act: a Plan becomes a closed-loop controller: its affine policy, or, when [mpc] is enabled, a
///    receding-horizon DDP on the same model warm-started from the plan (the paper's quadrotor);
///  - roll out on the real world: the controller sees noisy measurements, the world samples its
///    process noise; data rollouts also perturb the control (exploration) and record what was
///    measured; evaluation rollouts use the shared evaluation streams.

#include <functional>
#include <memory>
#include <string>
#include <random>
#include <vector>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/control/mpc.hpp"
#include "gpilqg/experiments/run_setup.hpp"

namespace gpilqg {

struct Plan {
  AffinePolicy policy;          ///< x_bar, u_bar, K (k = 0); what the result stores as iter_<k>/{x,u,K,k}
  double predicted_cost = 0.0;  ///< the solver's expected cost on its own model (with its noise terms)
  double nominal_cost = 0.0;    ///< the cost of the nominal trajectory x_bar, u_bar on that model
  double solve_seconds = 0.0;
  DdpSummary summary;
  std::shared_ptr<const StepModel> model;  ///< what MPC re-plans on (null: the policy only, e.g. PDDP's)
  DdpVariant variant = DdpVariant::ILQG;
  /// The start the solve began from (plan_with_ddp, the cheapest on the model): 0 the usual one,
  /// i >= 1 the closed-loop controls of plans_to_keep[i - 1].
  int start = 0;
};

/// A solve whose costs are not finite (its initial rollout diverged, summary.termination
/// InitialRolloutDiverged: DdpResult's costs are then +infinity) is scored like a diverged rollout
/// (trajectory.hpp): predicted and nominal cost, and the summary's costs, become the cost of the
/// states `reached` (the last one repeated), finite and large, so no result holds an infinity; the
/// termination says why. Plans with finite costs are left as they are.
void score_diverged_solve(Plan& plan, const Cost& cost, const Trajectory& reached);

/// The context of one task: config, task, models and cost (all outlive the actions), and where
/// progress lines go (may be empty).
class RunJournal;
struct SolveConfig;

struct TaskContext {
  const RunConfig& config;
  const RunTask& task;
  int task_index;
  const RunModels& models;
  const Cost& cost;
  std::function<void(const std::string&)> progress;
  RunJournal* journal = nullptr;  ///< where completed iterations are kept for --resume (null: nowhere)
  /// Threads for the work inside one iteration: the GP's outputs are fitted concurrently and PDDP's
  /// belief step shares its output pairs. The results do not depend on it.
  int threads = 2;
};

/// What every DDP solve of one task shares, whoever poses it (`gpilqg run`'s tasks, `gpilqg plan`'s
/// [problem]): the cost, the start, the horizon, the box limits, the initial controls and the solver.
struct DdpTask {
  const Cost* cost = nullptr;
  Vector x0;
  int horizon = 0;
  Vector u_min, u_max;  ///< empty: unconstrained
  Vector u_init;        ///< m: the constant controls a solve starts from when no better guess is known
  DdpOptions solver;    ///< the variant is chosen per solve
};

/// The DdpTask of a task of `gpilqg run`: its cost, x0 and horizon, [control] and [solver].
DdpTask ddp_task(const TaskContext& context);
/// The DdpTask of a `gpilqg solve` or `gpilqg plan` config with its `cost` (make_solve_cost): [problem]
/// (u_init zero when absent) and [solver].
DdpTask ddp_task(const SolveConfig& config, const Cost& cost);
/// The problem DDP solves for `task` on `model` (both must outlive it): cost, x0, horizon, limits.
DdpProblem ddp_problem(const DdpTask& task, const StepModel& model);

/// DDP on `model` (kept alive by the plan, for MPC) from the controls `u_start` (m x T; empty:
/// task.u_init repeated), within the task's limits; `variant` ILQG (process noise F) or RobustILQG (F
/// and the GP's G). Each of `plans_to_keep` (plans made on other models, reference_plans.hpp) is a
/// further start, its closed-loop controls on `model`; the solve begins at the start of least cost on
/// `model` (control/best_start.hpp), so it ends no dearer there than any of those plans.
Plan plan_with_ddp(const DdpTask& task, std::shared_ptr<const StepModel> model, DdpVariant variant,
                   const Matrix& u_start, const std::vector<AffinePolicy>& plans_to_keep = {});
/// The same for a task of `gpilqg run`.
Plan plan_with_ddp(const TaskContext& context, std::shared_ptr<const StepModel> model, DdpVariant variant,
                   const Matrix& u_start);

/// The plan of an algorithm that has no model yet: the open-loop controls config.u_init (PDDP before
/// it has data).
Plan open_loop_plan(const TaskContext& context);

/// A controller that acts on measured states (see the file comment). `holder` keeps the MPC state
/// alive for as long as the controller is used.
Controller make_controller(const TaskContext& context, const Plan& plan, std::unique_ptr<MpcController>& holder);

/// One rollout on the real world.
struct RealRollout {
  Trajectory truth;    ///< true states and applied controls
  int steps_completed = 0;  ///< transitions before a divergence (the horizon when finite)
  Matrix measured;     ///< n x (T+1): the measured states (what the controller saw, and x_T measured)
  bool finite = true;  ///< false: the world diverged (the trajectory holds the last finite state)
  double cost = 0.0;   ///< the task cost of the true trajectory
};

/// Where and how a controller runs on the (simulated) real world.
struct WorldRollout {
  const StepModel* world = nullptr;  ///< samples its process noise at every step
  Vector x0;
  int horizon = 0;
  Vector exploration_std;  ///< Gaussian noise added to every control (empty: none), then clamped
  Vector observation_std;  ///< the controller sees x + N(0, diag(std^2)); the log records what it saw
  Vector u_min, u_max;     ///< limits of the applied control (empty: none)
};

/// Runs `act` on setup.world: at each step the controller sees the measured state, exploration is
/// added to its control and the sum clamped to the limits. The rollout's cost is left 0 (the caller's
/// task knows its cost). Every draw comes from `rng`, in a fixed order, so equal seeds give equal
/// rollouts wherever they run (`gpilqg run` and `gpilqg rollout`).
RealRollout roll_out(const WorldRollout& setup, const Controller& act, std::mt19937_64& rng);

/// Runs `plan` on the world from the task's x0 for its horizon, with Gaussian exploration of std
/// `exploration` (empty: none) added to every control.
RealRollout roll_out(const TaskContext& context, const Plan& plan, const Vector& exploration, std::mt19937_64& rng);

/// Open-loop random excitation: each control drawn uniformly in u_init +- amplitude, held for 5 steps.
RealRollout random_rollout(const TaskContext& context, const Vector& amplitude, std::mt19937_64& rng);

/// The reported cost of a plan: the mean task cost of config.evaluation_rollouts rollouts on the
/// world, with the shared evaluation streams of `seed`.
struct Evaluation {
  double mean_cost = 0.0;
  std::vector<double> costs;
  Trajectory example;  ///< the first evaluation rollout (for the figures)
  int diverged = 0;
  double seconds = 0.0;
};
Evaluation evaluate(const TaskContext& context, const Plan& plan, std::uint64_t seed);

}  // namespace gpilqg
