#pragma once
/// @file mpc.hpp
/// Model predictive control with the DDP engine (the paper's "Robust-ILQG for a short horizon
/// repeatedly", used for the quadrotor): at every task step t the controller solves the window
/// [t, t + H) of the task cost from the measured state, warm-started from the previous plan shifted by
/// one step (its last control repeated), with a cap on iterations per step, and applies the first
/// control of the plan.

#include <random>
#include <vector>

#include "gpilqg/control/ddp_solver.hpp"

namespace gpilqg {

/// A view of a task cost over the window [offset, offset + H): stage t is the task's stage
/// offset + t, and the terminal cost is the task's terminal_at(offset + H).
class CostWindow final : public Cost {
 public:
  CostWindow(const Cost& task, int offset, int horizon) : task_(task), offset_(offset), horizon_(horizon) {}
  int state_dim() const override { return task_.state_dim(); }
  int control_dim() const override { return task_.control_dim(); }
  /// The task's workspace: the window evaluates the task's cost and nothing else.
  std::unique_ptr<CostWorkspace> make_workspace() const override { return task_.make_workspace(); }
  using Cost::stage;
  using Cost::terminal;
  double stage(int t, const VectorCRef& x, const VectorCRef& u, CostDerivatives* d,
               CostWorkspace& workspace) const override {
    return task_.stage(offset_ + t, x, u, d, workspace);
  }
  double terminal(const VectorCRef& x, CostDerivatives* d, CostWorkspace& workspace) const override {
    return task_.terminal_at(offset_ + horizon_, x, d, workspace);
  }
  void move_to(int offset) { offset_ = offset; }

 private:
  const Cost& task_;
  int offset_;
  int horizon_;
};

struct MpcOptions {
  int horizon = 50;                 ///< window length H in steps
  int first_solve_iterations = 100; ///< iteration cap of the first (cold) solve
  int iterations_per_step = 5;      ///< iteration cap of every warm-started solve
  DdpOptions solver;                ///< variant, tolerances, regularisation (max_iterations is overridden)
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

class MpcController {
 public:
  /// `model` plans, `task` is the cost of the whole task (stages 0..task_steps-1 and its end).
  /// Limits as in DdpProblem (empty: none). Throws std::invalid_argument on inconsistent input.
  MpcController(const StepModel& model, const Cost& task, MpcOptions options, Vector u_min = {},
                Vector u_max = {}, Matrix initial_plan = {});

  /// The control to apply at task step t from the measured state x; re-plans the window.
  Vector control(int t, const VectorCRef& x);

  const DdpResult& last_solution() const { return last_; }
  /// Summaries of every solve so far, in order.
  const std::vector<DdpSummary>& history() const { return history_; }

 private:
  const StepModel& model_;
  const Cost& task_;
  MpcOptions options_;
  Vector u_min_, u_max_;
  Matrix plan_;  ///< m x H warm start
  DdpSolver solver_;
  DdpResult last_;
  std::vector<DdpSummary> history_;
  int next_step_ = 0;
};

/// Closed-loop MPC on `world` for `steps` task steps from x0, sampling the world's noise (and
/// observation noise) as in rollout_policy. Stops early, with finite = false and `status` saying why,
/// if the world diverges (rollout.hpp).
struct MpcRun {
  Trajectory trajectory;  ///< true states and applied controls
  double cost = 0.0;      ///< the task cost of the run (stages plus terminal)
  int steps_completed = 0;
  bool finite = true;
  RolloutStatus status = RolloutStatus::Completed;
  double solve_seconds = 0.0;  ///< total time spent in the solver
};
MpcRun run_mpc(const StepModel& world, MpcController& controller, const Cost& task, const VectorCRef& x0,
               int steps, const PolicyRolloutSettings& settings, std::mt19937_64& rng);

}  // namespace gpilqg
