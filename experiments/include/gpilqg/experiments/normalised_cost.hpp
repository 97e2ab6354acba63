#pragma once
/// @file normalised_cost.hpp
/// An algorithm's cost relative to the reference (ilqg_real), and how precisely its evaluation
/// rollouts measure it.
///
/// Evaluation rollout i of every algorithm and iteration runs on the same noise stream i (common
/// random numbers, task_actions.hpp), so the costs a_i (the algorithm) and b_i (the reference) come in
/// pairs. The normalised cost is the ratio of their means, R = mean(a) / mean(b). Its standard error,
/// by the delta method for a ratio of paired means (the ratio estimator of survey sampling), is
///
///   se(R) = sqrt( sum_i d_i^2 / (E (E - 1)) ) / mean(b),     d_i = a_i - R b_i,
///
/// which the pairing makes much smaller than the spread of either cost alone: the noise that makes a
/// rollout expensive for one policy makes it expensive for the other. For E < 2 it cannot be
/// estimated and is reported as -1, as it is when a cost is not finite.

#include <vector>

namespace gpilqg {

struct NormalisedCost {
  double value = 0.0;            ///< R = mean(a) / mean(b)
  double standard_error = -1.0;  ///< se(R) above; -1 with fewer than two rollouts
};

/// R and se(R) from the paired rollout costs. Throws std::invalid_argument when the two have
/// different sizes, are empty, or the reference's mean is not positive and finite.
NormalisedCost normalised_cost(const std::vector<double>& costs, const std::vector<double>& reference_costs);

}  // namespace gpilqg
