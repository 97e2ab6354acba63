#pragma once
/// @file fit.hpp
/// Maximum-likelihood fitting (type-II ML, GPML book section 5.4.1), written once for all backends:
/// minimise the negative log marginal likelihood of a MarginalLikelihoodObjective over its parameter
/// vector with NLopt's L-BFGS (LD_LBFGS) inside the objective's box bounds.
///
/// Start points, in order: FitOptions::warm_start (if given, clipped to the bounds; a warm start of
/// another length, from a fit with a different number of backend-specific parameters such as FITC's
/// pseudo-inputs, contributes its D + 2 shared hyperparameters with this objective's extras), the objective's
/// data-driven initial values, then FitOptions::restarts random restarts (restart_parameters). The
/// start with the lowest NLML wins.
///
/// Each start is evaluated with its gradient g0 before NLopt begins; that evaluation answers NLopt's
/// first request (no point is evaluated twice; for the first start it is FitSummary::initial_nlml).
/// NLopt's variables are the parameters in units of a power of two near 1 / sqrt(max(1, |g0|_inf)),
/// so that L-BFGS's first trial step, steepest descent with unit length in its variables, moves no
/// parameter by more than about 1 (a factor of e in a log-parametrised quantity) instead of by
/// |g0|_inf, which grows with N. The tolerances are relative, hence the same in either unit.
///
/// Time limit (FitOptions::max_seconds > 0): measured from the call; each start gets NLopt's maxtime
/// set to the time left, which NLopt checks after every evaluation, and no start begins once none is
/// left. A fit stopped so keeps its best point so far and reports FitTermination::TimeLimit and the
/// starts begun (FitSummary::starts).
///
/// Numerical safeguards: an evaluation whose Cholesky needs jitter is counted and its largest jitter
/// reported. An evaluation that fails even with jitter returns +infinity from the objective; the
/// fitter never hands that (or a NaN) to NLopt. It returns a large finite value (1e10 (1 + |best
/// value seen|)) with a zero gradient instead: L-BFGS's line search sees a steep increase and
/// shortens the step, i.e. it backtracks into the region where K is positive definite. If every
/// start fails inside NLopt, the best point evaluated is returned with FitTermination::OptimiserError.

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

struct ParameterFit {
  Vector parameters;
  FitSummary summary;  ///< everything but backend, training_points and conditioning
};

/// Runs the fit. Throws std::invalid_argument for invalid options or a warm start shorter than the
/// shared hyperparameters.
ParameterFit fit_parameters(MarginalLikelihoodObjective& objective, const FitOptions& options);

}  // namespace gpilqg::gp
