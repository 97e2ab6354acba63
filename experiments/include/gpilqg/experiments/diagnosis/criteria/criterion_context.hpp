#pragma once
/// @file criterion_context.hpp
/// A fit context under a criterion: the criterion object made for the context's data and model
/// (criteria/criterion.hpp), with the residual and weights it defines.

#include "gpilqg/experiments/diagnosis/effect_fit.hpp"
#include "gpilqg/experiments/diagnosis/fit_criterion.hpp"

namespace gpilqg::diagnosis {

/// `context` under the criterion `criterion`, its object made for context.data and context.model.
/// One-step: the rest as given (its residual is the one-step residual). Simulation over windows of
/// `window` rows (SimulationCriterion): the windows' starts estimated when context.estimate_starts
/// (initial_state.hpp), and `residual` recomputed as the simulation error of context.model;
/// `restarts` (when not null) receives the restarts of that simulation. Inverse dynamics
/// (InverseDynamicsCriterion::make): the accelerations estimated, `residual` the generalised-force
/// residual of context.model (N x k) and `weights` its white-noise weights. Throws
/// std::invalid_argument for window < 1, and for inverse dynamics on a system
/// without a generalised-force map or on records too short for the acceleration estimate.
FitContext criterion_context(FitContext context, FitCriterion criterion, int window, int* restarts = nullptr);

}  // namespace gpilqg::diagnosis
