#include "gpilqg/control/best_start.hpp"

#include <stdexcept>

namespace gpilqg {

BestStart solve_from_best_start(DdpSolver& solver, const DdpProblem& problem, const std::vector<Matrix>& starts) {
  if (starts.empty()) throw std::invalid_argument("solve_from_best_start: no start");
  BestStart best{solver.solve(problem, starts.front()), 0};
  for (std::size_t i = 1; i < starts.size(); ++i) {
    DdpResult other = solver.solve(problem, starts[i]);
    if (other.expected_cost < best.result.expected_cost) best = {std::move(other), static_cast<int>(i)};
  }
  return best;
}

}  // namespace gpilqg
