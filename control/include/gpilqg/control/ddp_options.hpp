#pragma once
/// @file ddp_options.hpp
/// Settings of the DDP engine. Every field has a documented default; validate() rejects bad values
/// with a message naming the field.

#include <functional>
#include <optional>
#include <string_view>

namespace gpilqg {

struct DdpIteration;

/// Which stochastic terms enter the Q-expansion (paper, Robust-ILQG section, the sums in q, Q, g, G, H):
enum class DdpVariant {
  ILQR,        ///< none: Gauss-Newton DDP on the mean step
  ILQG,        ///< the process-noise columns F and their derivatives (Todorov and Li 2005)
  RobustILQG,  ///< F plus the model-uncertainty columns G and their derivatives (the paper)
};

/// Where the Levenberg-Marquardt term lambda I is added (Tassa, Erez and Todorov, IROS 2012, sec. II-F).
enum class RegularizationTarget {
  ControlHessian,  ///< Quu + lambda I: the classic damping of the control step
  ValueHessian,    ///< V'xx + lambda I inside every B' V'xx (.) product: keeps the step close in state space
};

std::optional<DdpVariant> parse_variant(std::string_view name);  ///< "ilqr", "ilqg", "robust_ilqg"
std::string_view to_string(DdpVariant variant);
std::optional<RegularizationTarget> parse_regularization(std::string_view name);  ///< "control", "value"
std::string_view to_string(RegularizationTarget target);

struct DdpOptions {
  DdpVariant variant = DdpVariant::ILQR;  ///< which Q-expansion terms to include
  int max_iterations = 500;               ///< cap on outer iterations (each: derivatives, backward, forward)
  double max_seconds = 60.0;              ///< wall-time cap [s], checked after every iteration
  /// Stop when an accepted step lowers the cost by less than this fraction of the cost
  /// (|J_old - J_new| <= tolerance * max(|J_old|, 1e-12)). The reference optimum needs ~1e-12.
  double cost_tolerance = 1e-9;
  /// Stop when the largest entry of the projected gradient dJ/du (controls at an active bound with the
  /// gradient pushing outwards count as zero) falls below this.
  double gradient_tolerance = 1e-8;

  RegularizationTarget regularization = RegularizationTarget::ControlHessian;
  double lambda_initial = 1.0;   ///< first regularisation value
  double lambda_factor = 1.6;    ///< multiplicative schedule: lambda grows by factor^k on failures
  double lambda_min = 1e-6;      ///< below this lambda is set to zero
  double lambda_max = 1e10;      ///< above this the solver gives up (termination RegularizationLimit)

  /// Line-search step lengths tried in order: 10^linspace(0, -3, line_search_steps).
  int line_search_steps = 11;
  /// Accept a step when actual / expected reduction exceeds this (0: any real decrease).
  double min_reduction_ratio = 0.0;

  /// Called on the solving thread after every iteration with its record (ddp_summary.hpp). Returning
  /// false stops the solve at once with termination Cancelled and the last accepted trajectory: the
  /// way progress lines and Ctrl-C (`gpilqg` from Python) reach inside a long solve. Empty: none.
  std::function<bool(const DdpIteration&)> on_iteration;

  /// Throws std::invalid_argument naming the field and the expected range.
  void validate() const;
};

}  // namespace gpilqg
