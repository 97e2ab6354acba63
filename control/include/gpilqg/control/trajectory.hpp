#pragma once
/// @file trajectory.hpp
/// A discrete trajectory: states x_0..x_T as the columns of an n x (T+1) matrix and controls
/// u_0..u_{T-1} as the columns of an m x T matrix (column t is time t dt).

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

}  // namespace gpilqg
