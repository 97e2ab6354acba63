#pragma once
/// @file best_start.hpp
/// DDP from several starts, keeping the best: the way a planner never ends in a worse local optimum
/// than a plan it already has (docs/solvers.md, "Plans that never lose").
///
/// DDP descends: every accepted step of its line search lowers the merit (the nominal cost plus the
/// trace terms of the current value Hessians, ddp_solver.hpp), so a solve started from the controls an
/// existing plan applies on the new model (closed_loop_controls) ends near or below that plan's cost
/// there, wherever a solve from the usual start ends. Keeping, of the solves from both starts, the one
/// of least expected cost under the new model gives a plan no worse on that model than either solve.

#include <vector>

#include "gpilqg/control/ddp_solver.hpp"

namespace gpilqg {

struct BestStart {
  DdpResult result;   ///< the solve of least expected cost (the earliest start on ties)
  int start = 0;      ///< its index in `starts`
};

/// Solves `problem` from each of `starts` (each m x T; at least one) and keeps the result of least
/// expected_cost. A start whose rollout diverges has an infinite cost and is kept only when all do.
/// Throws std::invalid_argument for no starts.
BestStart solve_from_best_start(DdpSolver& solver, const DdpProblem& problem, const std::vector<Matrix>& starts);

}  // namespace gpilqg
