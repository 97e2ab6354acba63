#include "gpilqg/control/best_start.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "gpilqg/control/rollout.hpp"
#include "gpilqg/control/trajectory.hpp"

namespace gpilqg {

double start_cost(const DdpProblem& problem, const Matrix& controls) {
  Matrix u = controls;
  if (problem.u_min.size()) u = u.cwiseMax(problem.u_min.replicate(1, u.cols()));
  if (problem.u_max.size()) u = u.cwiseMin(problem.u_max.replicate(1, u.cols()));
  const RolloutResult r = rollout(*problem.model, problem.x0, u);
  if (!r.finite) return std::numeric_limits<double>::infinity();
  const double cost = trajectory_cost(*problem.cost, r.trajectory);
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
}

BestStart solve_from_best_start(DdpSolver& solver, const DdpProblem& problem, const std::vector<Matrix>& starts) {
  if (starts.empty()) throw std::invalid_argument("solve_from_best_start: no start");
  BestStart best;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    best.start_costs.push_back(starts.size() == 1 ? 0.0 : start_cost(problem, starts[i]));
    if (best.start_costs[i] < best.start_costs[static_cast<std::size_t>(best.start)]) best.start = static_cast<int>(i);
  }
  best.result = solver.solve(problem, starts[static_cast<std::size_t>(best.start)]);
  return best;
}

}  // namespace gpilqg
