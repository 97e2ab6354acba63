#pragma once
/// @file trajectory.hpp
/// A discrete trajectory: states x_0..x_T as the columns of an n x (T+1) matrix and controls
/// u_0..u_{T-1} as the columns of an m x T matrix (column t is time t dt).

#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/types.hpp"

namespace gpilqg {

struct Trajectory {
  Matrix x;  ///< n x (T+1)
  Matrix u;  ///< m x T

  Trajectory() = default;
  /// Zero-filled trajectory of `horizon` steps.
  Trajectory(int state_dim, int control_dim, int horizon);

  int horizon() const { return static_cast<int>(u.cols()); }
  int state_dim() const { return static_cast<int>(x.rows()); }
  int control_dim() const { return static_cast<int>(u.rows()); }
};

/// The cost of a whole trajectory: sum_{t<T} l_t(x_t, u_t) + l_T(x_T), the terminal taken as
/// cost.terminal_at(T) (so a task cost viewed through a longer horizon is scored at its own end).
/// A diverged rollout repeats its last finite state (rollout.hpp), so its cost stays finite and large.
double trajectory_cost(const Cost& cost, const Trajectory& trajectory);

}  // namespace gpilqg
