#pragma once
/// @file peer_cases.hpp
/// The units of work compare_peers.py sets against a peer, each timed here with repetitions
/// (peer_timing.hpp) and returned as JSON with the numbers the script checks against the peer.
/// `threads` is the library's own thread count for one evaluation (ExactGpOptions::threads,
/// FitcOptions::threads); nothing else runs in parallel.
///
///  a. nlml_case:    NLML and its gradient of the exact GP on the first n rows (GPML eqs. 2.30, 5.9)
///  b. fit_case:     a whole exact-GP fit on the first n rows: one start, the data-driven initial values,
///                   NLopt L-BFGS in the data-driven box, then conditioning (GpBackend::fit, fit.hpp);
///                   case e is the same call at every N of fit_sizes (its peer starts from its own
///                   default instead of from gpilqg's start)
///  c. fitc_case:    FITC NLML and its gradient, hyperparameters and pseudo-inputs (fitc.hpp)
///  d. predict_case: latent mean and variance of the exact GP conditioned on the first n rows at every
///                   test point, in one batched call (FittedGp::predict(points, mean, variance))
///
/// The cheap cases (a, c, d) run once untimed first (allocation of workspaces), then `repeats` timed
/// runs; a fit is timed from its first run, `repeats` times.

#include <nlohmann/json.hpp>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/training_set.hpp"

namespace gpilqg::bench {

nlohmann::json nlml_case(const gp::TrainingSet& data, int n, const Vector& theta, int threads, int repeats);
nlohmann::json fit_case(const gp::TrainingSet& data, int n, int threads, int repeats);
nlohmann::json fitc_case(const gp::TrainingSet& data, const Vector& theta, int threads, int repeats);
nlohmann::json predict_case(const gp::TrainingSet& data, int n, const Vector& theta, const Matrix& points,
                            int threads, int repeats);

}  // namespace gpilqg::bench
