#pragma once
/// @file ddp_summary.hpp
/// What a solve did: why it stopped, the per-iteration trace, and where the time went.

#include <string>
#include <string_view>
#include <vector>

namespace gpilqg {

enum class DdpTermination {
  CostChange,          ///< an accepted step improved the cost by less than cost_tolerance
  GradientNorm,        ///< the projected gradient fell below gradient_tolerance
  MaxIterations,       ///< max_iterations reached
  WallTime,            ///< max_seconds reached
  RegularizationLimit, ///< no acceptable step even at lambda_max (numerical trouble or a local minimum)
  InitialRolloutDiverged,  ///< the initial controls drive the model to non-finite states
  Cancelled,           ///< DdpOptions::on_iteration asked to stop
  /// An accepted step changed the cost by less than cost_tolerance, but the projected gradient g is
  /// not finite or absurd: |g|_inf max(|u|_inf, 1) > 1e3 max(|J|, 1) (stationary() below).
  /// The line search only found tiny steps on a trajectory too sensitive to its controls for the
  /// quadratic model (e.g. a step dt far too long for the dynamics): not a minimum, not converged.
  Stalled,
};

std::string_view to_string(DdpTermination termination);
/// True for the terminations that mean convergence (CostChange, GradientNorm); Stalled is not.
bool converged(DdpTermination termination);

/// Whether a trajectory whose cost stopped changing is a minimum rather than a stall: the projected
/// gradient g = dJ/du (its largest entry over all steps) is finite and its first-order effect over
/// the controls' own scale is not absurd against the cost,
///   |g|_inf max(|u|_inf, 1) <= kStationarityFactor max(|J|, 1),   kStationarityFactor = 1e3.
/// Measured ratios |g| max(|u|, 1) / max(|J|, 1): the reference cart-pole swing-ups 1e-7 to 1e-4, a
/// stiff acrobot swing-up stopped at a relative cost change of 1e-9 about 50 (large curvature: its
/// Newton step predicts a further reduction of 2e-6 J), and a line search stalled on a trajectory too
/// sensitive to its controls about 1e53 (the cart-pole at dt = 1 s, whose Newton step predicts nothing
/// because the curvature is as absurd). The floors at 1 only make the test more lenient.
inline constexpr double kStationarityFactor = 1e3;
bool stationary(double gradient_norm, double control_scale, double cost);

struct DdpIteration {
  int iteration = 0;
  double cost = 0.0;                ///< merit (expected cost) after the iteration
  double lambda = 0.0;              ///< regularisation used by the accepted backward pass
  double step = 0.0;                ///< accepted line-search step (0 when rejected)
  double expected_reduction = 0.0;  ///< predicted by the quadratic model for that step
  double actual_reduction = 0.0;    ///< achieved (0 when rejected)
  double gradient_norm = 0.0;       ///< max |projected dJ/du| at the start of the iteration
  int backward_failures = 0;        ///< backward passes rejected (non-PD Quu) before this one passed
  int line_search_trials = 0;       ///< forward passes tried by the line search
  bool accepted = false;
};

struct DdpTimings {
  double derivatives_s = 0.0;  ///< model and cost derivatives along the trajectory
  double backward_s = 0.0;     ///< backward passes (including rejected ones)
  double forward_s = 0.0;      ///< forward passes of the line search
  double total_s = 0.0;        ///< the whole solve
};

struct DdpSummary {
  DdpTermination termination = DdpTermination::MaxIterations;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;         ///< the merit at the returned trajectory
  double final_gradient_norm = 0.0;
  /// True when no backward pass (lambda from 0 to lambda_max) succeeded at the returned trajectory:
  /// the result's policy is then open loop (K = 0), its value Hessians and gradient are zero and its
  /// expected cost is the last accepted merit. Only after termination RegularizationLimit.
  bool final_backward_failed = false;
  std::vector<DdpIteration> trace;
  DdpTimings timings;

  /// One line, e.g. "ilqr: gradient_norm after 139 iterations, cost 5.70e+02 -> 6.45e-01, |g| 9.1e-09, 4.2 ms".
  std::string report(std::string_view label) const;
};

}  // namespace gpilqg
