#include "gpilqg/control/ddp_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gpilqg {

std::string_view to_string(DdpTermination termination) {
  switch (termination) {
    case DdpTermination::CostChange: return "cost_change";
    case DdpTermination::GradientNorm: return "gradient_norm";
    case DdpTermination::MaxIterations: return "max_iterations";
    case DdpTermination::WallTime: return "wall_time";
    case DdpTermination::RegularizationLimit: return "regularization_limit";
    case DdpTermination::InitialRolloutDiverged: return "initial_rollout_diverged";
    case DdpTermination::Cancelled: return "cancelled";
    case DdpTermination::Stalled: return "stalled";
  }
  return "?";
}

bool converged(DdpTermination termination) {
  return termination == DdpTermination::CostChange || termination == DdpTermination::GradientNorm;
}

bool stationary(double gradient_norm, double control_scale, double cost) {
  if (!std::isfinite(gradient_norm) || !std::isfinite(control_scale) || !std::isfinite(cost)) return false;
  return gradient_norm * std::max(std::abs(control_scale), 1.0) <= kStationarityFactor * std::max(std::abs(cost), 1.0);
}

std::string DdpSummary::report(std::string_view label) const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%.*s: %.*s after %d iterations, cost %.6e -> %.12e, |g| %.1e, %.2f ms",
                static_cast<int>(label.size()), label.data(),
                static_cast<int>(to_string(termination).size()), to_string(termination).data(), iterations,
                initial_cost, final_cost, final_gradient_norm, 1e3 * timings.total_s);
  return buffer;
}

}  // namespace gpilqg
