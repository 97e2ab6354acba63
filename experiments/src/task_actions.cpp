#include "gpilqg/experiments/task_actions.hpp"

#include <chrono>
#include <cmath>

#include "gpilqg/control/best_start.hpp"
#include "gpilqg/control/rollout.hpp"

#include "gpilqg/experiments/solve_config.hpp"

#include "elapsed_seconds.hpp"

namespace gpilqg {
namespace {

Matrix repeated_u_init(const TaskContext& c) { return c.config.u_init.replicate(1, c.task.horizon); }

}  // namespace

void score_diverged_solve(Plan& plan, const Cost& cost, const Trajectory& reached) {
  if (std::isfinite(plan.predicted_cost) && std::isfinite(plan.nominal_cost)) return;
  const double scored = trajectory_cost(cost, reached);
  plan.predicted_cost = plan.nominal_cost = scored;
  plan.summary.initial_cost = plan.summary.final_cost = scored;
}

DdpTask ddp_task(const TaskContext& c) {
  DdpTask task;
  task.cost = &c.cost;
  task.x0 = c.task.x0;
  task.horizon = c.task.horizon;
  task.u_min = c.config.u_min;
  task.u_max = c.config.u_max;
  task.u_init = c.config.u_init;
  task.solver = c.config.solver;
  return task;
}

DdpTask ddp_task(const SolveConfig& c, const Cost& cost) {
  DdpTask task;
  task.cost = &cost;
  task.x0 = c.x0;
  task.horizon = c.horizon;
  task.u_min = c.u_min;
  task.u_max = c.u_max;
  task.u_init = c.u_init.size() ? c.u_init : Vector(Vector::Zero(c.R.size()));
  task.solver = c.solver;
  return task;
}

DdpProblem ddp_problem(const DdpTask& task, const StepModel& model) {
  DdpProblem problem;
  problem.model = &model;
  problem.cost = task.cost;
  problem.x0 = task.x0;
  problem.horizon = task.horizon;
  problem.u_min = task.u_min;
  problem.u_max = task.u_max;
  return problem;
}

Plan plan_with_ddp(const DdpTask& task, std::shared_ptr<const StepModel> model, DdpVariant variant,
                   const Matrix& u_start, const std::vector<AffinePolicy>& plans_to_keep) {
  const DdpProblem problem = ddp_problem(task, *model);
  DdpOptions options = task.solver;
  options.variant = variant;
  DdpSolver solver(options);
  const auto start = std::chrono::steady_clock::now();
  std::vector<Matrix> starts{u_start.size() ? u_start : Matrix(task.u_init.replicate(1, task.horizon))};
  for (const AffinePolicy& kept : plans_to_keep) starts.push_back(closed_loop_controls(*model, kept, task.x0));
  BestStart best = solve_from_best_start(solver, problem, starts);
  Plan plan;
  plan.solve_seconds = seconds_since(start);
  plan.start = best.start;
  plan.policy = std::move(best.result.policy);
  plan.predicted_cost = best.result.expected_cost;
  plan.nominal_cost = best.result.nominal_cost;
  plan.summary = std::move(best.result.summary);
  plan.model = std::move(model);
  plan.variant = variant;
  score_diverged_solve(plan, *task.cost, best.result.trajectory);
  return plan;
}

Plan plan_with_ddp(const TaskContext& c, std::shared_ptr<const StepModel> model, DdpVariant variant,
                   const Matrix& u_start) {
  return plan_with_ddp(ddp_task(c), std::move(model), variant, u_start);
}

Plan open_loop_plan(const TaskContext& c) {
  const int n = static_cast<int>(c.task.x0.size());
  const int m = static_cast<int>(c.config.u_init.size());
  const int T = c.task.horizon;
  Plan plan;
  plan.policy.x_bar = c.task.x0.replicate(1, T + 1);
  plan.policy.u_bar = repeated_u_init(c);
  plan.policy.k = Matrix::Zero(m, T);
  plan.policy.K.assign(static_cast<std::size_t>(T), Matrix::Zero(m, n));
  plan.policy.u_min = c.config.u_min;
  plan.policy.u_max = c.config.u_max;
  return plan;
}

Controller make_controller(const TaskContext& c, const Plan& plan, std::unique_ptr<MpcController>& holder) {
  if (!c.config.mpc || plan.model == nullptr) {
    holder.reset();
    const AffinePolicy* policy = &plan.policy;
    return [policy](int t, const VectorCRef& x, VectorRef u) { policy->control(t, x, u); };
  }
  MpcOptions options = c.config.mpc_options;
  options.solver = c.config.solver;
  options.solver.variant = plan.variant;
  const int H = std::min(options.horizon, plan.policy.horizon());
  Matrix warm = plan.policy.u_bar.leftCols(H);
  holder = std::make_unique<MpcController>(*plan.model, c.cost, options, c.config.u_min, c.config.u_max, warm);
  MpcController* mpc = holder.get();
  return [mpc](int t, const VectorCRef& x, VectorRef u) { u = mpc->control(t, x); };
}

RealRollout roll_out(const WorldRollout& setup, const Controller& act, std::mt19937_64& rng) {
  const int T = setup.horizon;
  RealRollout out;
  out.measured.resize(setup.x0.size(), T + 1);
  std::normal_distribution<double> standard_normal;
  const Vector& exploration = setup.exploration_std;
  const Controller explore = [&](int t, const VectorCRef& observed, VectorRef u) {
    out.measured.col(t) = observed;
    act(t, observed, u);
    for (Eigen::Index j = 0; j < exploration.size(); ++j) u(j) += exploration(j) * standard_normal(rng);
    if (setup.u_min.size()) u = u.cwiseMax(setup.u_min);
    if (setup.u_max.size()) u = u.cwiseMin(setup.u_max);
  };
  RolloutResult r = closed_loop_rollout(*setup.world, setup.x0, T, explore, RolloutNoise::Process,
                                        setup.observation_std, &rng);
  Vector last = r.trajectory.x.col(T);
  add_observation_noise(setup.observation_std, rng, last);
  out.measured.col(T) = last;
  // A diverged rollout stops calling the controller: its remaining measurements repeat the last state.
  for (int t = r.steps_completed + 1; t <= T; ++t) out.measured.col(t) = r.trajectory.x.col(t);
  out.finite = r.finite;
  out.steps_completed = r.steps_completed;
  out.truth = std::move(r.trajectory);
  return out;
}

RealRollout roll_out(const TaskContext& c, const Plan& plan, const Vector& exploration, std::mt19937_64& rng) {
  std::unique_ptr<MpcController> holder;
  const Controller act = make_controller(c, plan, holder);
  WorldRollout setup;
  setup.world = c.models.world.get();
  setup.x0 = c.task.x0;
  setup.horizon = c.task.horizon;
  setup.exploration_std = exploration;
  setup.observation_std = c.config.observation_std;
  setup.u_min = c.config.u_min;
  setup.u_max = c.config.u_max;
  RealRollout out = roll_out(setup, act, rng);
  out.cost = trajectory_cost(c.cost, out.truth);
  return out;
}

RealRollout random_rollout(const TaskContext& c, const Vector& amplitude, std::mt19937_64& rng) {
  const int m = static_cast<int>(c.config.u_init.size());
  const int T = c.task.horizon;
  constexpr int kHoldSteps = 5;
  Plan plan = open_loop_plan(c);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int t = 0; t < T; t += kHoldSteps) {
    Vector level(m);
    for (int j = 0; j < m; ++j) level(j) = c.config.u_init(j) + amplitude(j) * unit(rng);
    if (c.config.u_min.size()) level = level.cwiseMax(c.config.u_min);
    if (c.config.u_max.size()) level = level.cwiseMin(c.config.u_max);
    for (int s = t; s < std::min(T, t + kHoldSteps); ++s) plan.policy.u_bar.col(s) = level;
  }
  return roll_out(c, plan, Vector(), rng);
}

Evaluation evaluate(const TaskContext& c, const Plan& plan, std::uint64_t seed) {
  const auto start = std::chrono::steady_clock::now();
  Evaluation e;
  for (int i = 0; i < c.config.evaluation_rollouts; ++i) {
    auto rng = make_rng(seed, c.task_index, RandomStream::Evaluation, {static_cast<std::uint64_t>(i)});
    RealRollout r = roll_out(c, plan, Vector(), rng);
    e.costs.push_back(r.cost);
    e.diverged += r.finite ? 0 : 1;
    if (i == 0) e.example = std::move(r.truth);
  }
  double sum = 0.0;
  for (const double cost : e.costs) sum += cost;
  e.mean_cost = sum / static_cast<double>(e.costs.size());
  e.seconds = seconds_since(start);
  return e;
}

}  // namespace gpilqg
