#pragma once
/// @file fitted_moment_matcher.hpp
/// Which GP backends can serve PDDP, and the moment matcher (moment_matcher.hpp) of a set of fitted
/// GPs, one per output. The choice follows the fitted model, so PDDP's belief dynamics
/// (gp_belief_dynamics.hpp) work with any backend that has closed-form Gaussian expectations:
///
///   "exact"    SeArdMomentMatcher over each output's training points (the subsample; the outputs
///              share it when fitted with the same seed), beta and Kinv re-conditioned from the
///              fitted hyperparameters (condition_se_ard_output)
///   "fitc"     SeArdMomentMatcher with per-output centres: each output's pseudo-inputs Xu_a, and
///              FitcPredictor's beta and Kinv = -C = Kuu^-1 - (Kuu + Kuf Lambda^-1 Kfu)^-1, so the
///              posterior mean and latent variance are exactly the predictor's
///   "ssgp"     SsgpMomentMatcher on each output's frequencies, weights alpha and C = sn^2 A^-1
///   "compact"  none: the Wendland kernel has no closed-form expectation under a Gaussian input

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gpilqg/gp/backend.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp {

/// The registry names (backend_registry.hpp) whose fitted models have exact moment matching, in
/// registry order: "exact", "fitc", "ssgp".
std::vector<std::string> moment_matching_backends();

/// Throws std::invalid_argument, starting with `who` (when not empty), unless `backend` is one of
/// moment_matching_backends(); the message says why (for "compact": no closed-form expectation of
/// the Wendland kernel) and lists the backends that serve.
void require_moment_matching(std::string_view backend, std::string_view who);

/// The moment matcher of `outputs` (E >= 1 fitted GPs, one per output, all from one backend and on
/// the same D inputs; zero-mean, as every backend is). Throws std::invalid_argument when `outputs`
/// is empty or holds a null pointer, the backends or input dimensions differ, or the backend has no
/// moment matching (require_moment_matching's message).
std::shared_ptr<const MomentMatcher> moment_matcher_for(const std::vector<const FittedGp*>& outputs);

}  // namespace gpilqg::gp
