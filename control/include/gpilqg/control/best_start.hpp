#pragma once
/// @file best_start.hpp
/// DDP from the best of several starts: the way a planner never ends worse than a plan it already has
/// (docs/solvers.md, "Plans that never lose").
///
/// DDP descends: every accepted step of its line search lowers the merit (the nominal cost plus the
/// trace terms of the current value Hessians, ddp_solver.hpp), so a solve ends at or below the cost of
/// the controls it starts from. Each start is rolled out on the problem's model (its nominal cost,
/// +infinity when the rollout diverges) and the solve starts from the cheapest: a plan made on another
/// model, entered as the controls its feedback applies on this one (closed_loop_controls), then bounds
/// the result by what that plan costs here. One solve, whatever the number of starts.

#include <vector>

#include "gpilqg/control/ddp_solver.hpp"

namespace gpilqg {

struct BestStart {
  DdpResult result;               ///< the solve from the cheapest start
  int start = 0;                  ///< its index in `starts` (the earliest on ties)
  /// Each start's nominal cost on the model (+infinity: diverged). A single start is not rolled out
  /// (there is nothing to choose): its entry is 0.
  std::vector<double> start_costs;
};

/// The nominal cost of rolling `controls` (m x T, clamped to the problem's limits) out on the problem's
/// model from x0: +infinity when the rollout diverges.
double start_cost(const DdpProblem& problem, const Matrix& controls);

/// Solves `problem` from the start of least start_cost (each m x T; at least one). Throws
/// std::invalid_argument for no starts.
BestStart solve_from_best_start(DdpSolver& solver, const DdpProblem& problem, const std::vector<Matrix>& starts);

}  // namespace gpilqg
