#pragma once
/// @file ddp_problem.hpp
/// A finite-horizon optimal control problem: minimise E[ l_T(x_T) + sum_t l_t(x_t, u_t) ] over
/// T steps of a StepModel from x0, optionally with box limits on u (paper eq. for J(x_0)).

#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/step_model.hpp"

namespace gpilqg {

struct DdpProblem {
  const StepModel* model = nullptr;  ///< not owned; must outlive the solve
  const Cost* cost = nullptr;        ///< not owned; must outlive the solve
  Vector x0;                         ///< initial state (n)
  int horizon = 0;                   ///< T >= 1
  Vector u_min;                      ///< lower limits (m) or empty for none; may hold -inf entries
  Vector u_max;                      ///< upper limits (m) or empty for none; may hold +inf entries

  bool has_limits() const { return u_min.size() > 0 || u_max.size() > 0; }
  /// Throws std::invalid_argument naming what is wrong (null model, size mismatch, u_min > u_max...).
  void validate() const;
};

}  // namespace gpilqg
