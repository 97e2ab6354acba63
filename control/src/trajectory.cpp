#include "gpilqg/control/trajectory.hpp"

#include <stdexcept>
#include <string>

namespace gpilqg {

Trajectory::Trajectory(int state_dim, int control_dim, int horizon)
    : x(Matrix::Zero(state_dim, horizon + 1)), u(Matrix::Zero(control_dim, horizon)) {
  if (state_dim < 1 || control_dim < 0 || horizon < 0)
    throw std::invalid_argument("Trajectory(" + std::to_string(state_dim) + ", " +
                                std::to_string(control_dim) + ", " + std::to_string(horizon) +
                                "): expected n >= 1, m >= 0, T >= 0");
}

double trajectory_cost(const Cost& cost, const Trajectory& trajectory) {
  const int T = trajectory.horizon();
  const auto workspace = cost.make_workspace();
  double J = cost.terminal_at(T, trajectory.x.col(T), nullptr, *workspace);
  for (int t = 0; t < T; ++t) J += cost.stage(t, trajectory.x.col(t), trajectory.u.col(t), nullptr, *workspace);
  return J;
}

}  // namespace gpilqg
