#pragma once
/// @file ddp_solver.hpp
/// One DDP engine for iLQR, iLQG and Robust-iLQG (the paper's Robust-ILQG section).
///
/// Backward pass (paper, the expansion with terms q, Q, g, G, H). With the discrete diffusion columns
/// c_i = sqrt(dt) F^(i) (and, for Robust-iLQG, also sqrt(dt) G^(j)), S' = V'_xx and s' = V'_x:
///
///   Q_x  = l_x  + A' s'       + sum_i c_ix' S' c_i        (paper: q)
///   Q_u  = l_u  + B' s'       + sum_i c_iu' S' c_i        (paper: g)
///   Q_xx = l_xx + A' S' A     + sum_i c_ix' S' c_ix       (paper: Q)
///   Q_ux = l_ux + B' S' A     + sum_i c_iu' S' c_ix       (paper: G)
///   Q_uu = l_uu + B' S' B     + sum_i c_iu' S' c_iu       (paper: H)
///   constant: l + s'_0 + 0.5 sum_i c_i' S' c_i            (the trace terms of the expected cost)
///
/// with c_ix = d c_i / dx (n x n) and c_iu = d c_i / du (n x m). iLQR includes no columns, iLQG the
/// process-noise columns F, Robust-iLQG F and the model-uncertainty columns G: that choice is the only
/// difference between the variants. The step is (k, K) = argmin of the Q-model, by a projected-Newton
/// box QP when the controls are limited (rows of K for clamped controls are zero), then
///   V_x  = Q_x + K' Q_uu k + K' Q_u + Q_ux' k,   V_xx = Q_xx + K' Q_uu K + K' Q_ux + Q_ux' K.
///
/// The merit is the expected cost to second order: the nominal cost plus sum_t 0.5 sum_i c_i' S_{t+1} c_i
/// with S held at the last backward pass, so the line search measures the same quantity whose
/// reduction the backward pass predicts (expected reduction alpha dV_1 + alpha^2 dV_2). For iLQR the
/// merit is the nominal cost.
///
/// The solver object owns every per-step buffer; they are sized once per problem shape and reused by
/// later solves of the same shape (MPC), so iterations do not allocate.

#include <memory>

#include "gpilqg/control/ddp_options.hpp"
#include "gpilqg/control/ddp_problem.hpp"
#include "gpilqg/control/ddp_summary.hpp"
#include "gpilqg/control/policy.hpp"
#include "gpilqg/control/trajectory.hpp"

namespace gpilqg {

struct DdpResult {
  Trajectory trajectory;   ///< the optimised nominal trajectory
  AffinePolicy policy;     ///< feedback around it (k = 0), clamped to the problem's limits
  DdpSummary summary;
  /// l_T(x_T) + sum_t l_t(x_t, u_t) along the nominal trajectory. +infinity (as is expected_cost) when
  /// summary.termination == InitialRolloutDiverged: the initial controls drive the model beyond the
  /// divergence bound of rollout.hpp; the trajectory then holds the states reached, the last one
  /// repeated. Nothing in a result is ever NaN.
  double nominal_cost = 0.0;
  double expected_cost = 0.0;   ///< nominal_cost plus the trace terms: the predicted E[J] of the policy
  std::vector<Matrix> value_hessians;  ///< S_t = V_xx at t = 0..T along the returned trajectory
  /// dM/du_t (m x T) at the returned trajectory, M the merit with S = value_hessians held fixed:
  /// M(u) = l_T(x_T) + sum_t [ l_t(x_t, u_t) + 0.5 sum_i c_i(x_t, u_t)' S_{t+1} c_i(x_t, u_t) ] along the
  /// open-loop rollout of u. Not projected onto the limits (the summary's gradient norm is).
  Matrix gradient;
};

/// The per-step buffers of one problem shape (defined in ddp_solver.cpp).
struct DdpWorkspace;

class DdpSolver {
 public:
  /// Throws std::invalid_argument when the options are invalid.
  explicit DdpSolver(DdpOptions options = {});
  ~DdpSolver();
  DdpSolver(DdpSolver&&) noexcept;
  DdpSolver& operator=(DdpSolver&&) noexcept;

  const DdpOptions& options() const { return options_; }
  /// Replaces the options (validated); the buffers stay.
  void set_options(DdpOptions options);

  /// Solves from the initial control sequence (m x T, clamped to the limits first). Numerical trouble
  /// (non-positive-definite Q_uu, a rejected line search) raises the regularisation and is reported in
  /// the summary; only invalid input throws (std::invalid_argument).
  DdpResult solve(const DdpProblem& problem, const Matrix& initial_controls);

 private:
  DdpOptions options_;
  std::unique_ptr<DdpWorkspace> ws_;
};

}  // namespace gpilqg
