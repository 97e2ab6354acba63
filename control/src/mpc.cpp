#include "gpilqg/control/mpc.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

void MpcOptions::validate() const {
  if (horizon < 1) throw std::invalid_argument("mpc option 'horizon' = " + std::to_string(horizon) + "; expected >= 1");
  if (first_solve_iterations < 1)
    throw std::invalid_argument("mpc option 'first_solve_iterations' = " + std::to_string(first_solve_iterations) +
                                "; expected >= 1");
  if (iterations_per_step < 1)
    throw std::invalid_argument("mpc option 'iterations_per_step' = " + std::to_string(iterations_per_step) +
                                "; expected >= 1");
  solver.validate();
}

MpcController::MpcController(const StepModel& model, const Cost& task, MpcOptions options, Vector u_min,
                             Vector u_max, Matrix initial_plan)
    : model_(model),
      task_(task),
      options_(std::move(options)),
      u_min_(std::move(u_min)),
      u_max_(std::move(u_max)),
      plan_(std::move(initial_plan)),
      solver_(options_.solver) {
  options_.validate();
  const int m = model_.control_dim();
  if (plan_.size() == 0) plan_ = Matrix::Zero(m, options_.horizon);
  if (plan_.rows() != m || plan_.cols() != options_.horizon)
    throw std::invalid_argument("mpc: the initial plan is " + std::to_string(plan_.rows()) + "x" +
                                std::to_string(plan_.cols()) + "; expected " + std::to_string(m) + "x" +
                                std::to_string(options_.horizon));
}

Vector MpcController::control(int t, const VectorCRef& x) {
  CostWindow window(task_, t, options_.horizon);
  DdpProblem problem;
  problem.model = &model_;
  problem.cost = &window;
  problem.x0 = x;
  problem.horizon = options_.horizon;
  problem.u_min = u_min_;
  problem.u_max = u_max_;
  DdpOptions o = options_.solver;
  o.max_iterations = history_.empty() ? options_.first_solve_iterations : options_.iterations_per_step;
  solver_.set_options(o);
  last_ = solver_.solve(problem, plan_);
  history_.push_back(last_.summary);
  next_step_ = t + 1;

  // Warm start for the next step: the plan shifted by one, the last control repeated.
  const int H = options_.horizon;
  if (H > 1) plan_.leftCols(H - 1) = last_.trajectory.u.rightCols(H - 1);
  plan_.col(H - 1) = last_.trajectory.u.col(H - 1);
  return last_.trajectory.u.col(0);
}

MpcRun run_mpc(const StepModel& world, MpcController& controller, const Cost& task, const VectorCRef& x0,
               int steps, const PolicyRolloutSettings& settings, std::mt19937_64& rng) {
  if (steps < 1) throw std::invalid_argument("mpc run: steps = " + std::to_string(steps) + "; expected >= 1");
  MpcRun run;
  const Controller replan = [&](int t, const VectorCRef& observed, VectorRef u) {
    u = controller.control(t, observed);
    run.solve_seconds += controller.last_solution().summary.timings.total_s;
  };
  const RolloutResult r =
      closed_loop_rollout(world, x0, steps, replan, settings.noise(), settings.observation_std, &rng);
  run.trajectory = r.trajectory;
  run.steps_completed = r.steps_completed;
  run.finite = r.finite;
  run.cost = trajectory_cost(task, run.trajectory);  // a diverged run is scored at its last finite state
  return run;
}

}  // namespace gpilqg
