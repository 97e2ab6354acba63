/// The memory estimate of a trajectory optimisation (limits.hpp).

#include "gpilqg/core/limits.hpp"

#include <fmt/format.h>

namespace gpilqg::limits {

double trajectory_bytes(long horizon, long n, long m, bool belief_space) {
  const double N = static_cast<double>(n), M = static_cast<double>(m);
  const double belief = belief_space ? N + N * N : N;  // PDDP propagates the mean and the covariance
  const double per_step = 2.0 * (belief + M)            // nominal and candidate trajectories
                          + belief * belief + belief * M  // f_x, f_u (of the belief dynamics)
                          + belief + belief * belief + M + M * M + belief * M  // l_x, l_xx, l_u, l_uu, l_ux
                          + M + M * belief                // k, K
                          + belief + belief * belief;     // V_x, V_xx
  return 2.0 * 8.0 * per_step * static_cast<double>(horizon + 1);
}

std::optional<std::string> trajectory_memory_problem(long horizon, long n, long m, bool belief_space) {
  const double bytes = trajectory_bytes(horizon, n, m, belief_space);
  if (bytes <= kMemoryBudgetBytes) return std::nullopt;
  constexpr double kGb = 1ull << 30;
  return fmt::format("{} steps of {} {}states and {} controls need about {:.1f} GB for the solver's per-step matrices, "
                     "more than the budget of {:.0f} GB",
                     horizon, n, belief_space ? "(belief-space) " : "", m, bytes / kGb, kMemoryBudgetBytes / kGb);
}

}  // namespace gpilqg::limits
