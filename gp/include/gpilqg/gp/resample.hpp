#pragma once
/// @file resample.hpp
/// The paper's guard against a bad subsample (GP-ILQG, section "Experiments": "If the learner's
/// prediction error for a validation set is higher than that of its previous learner, we re-sample
/// and re-train"): fit; if the new model's validation MSE exceeds the previous learner's, fit again on
/// a fresh subsample (a new seed), at most `max_resamples` times; return the attempt with the lowest
/// validation error and report every attempt.

#include <string>
#include <vector>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

struct ResampleOptions {
  int max_resamples = 3;  ///< re-fits after the first attempt (0: never re-sample)
  void validate() const;  ///< throws std::invalid_argument when negative
};

struct ResampleReport {
  double previous_validation_mse = -1.0;  ///< the previous learner's error; -1 without one
  std::vector<double> validation_mse;     ///< one entry per attempt
  int chosen_attempt = 0;
  /// True when the chosen model is no worse than the previous learner (always true without one).
  bool improved = true;
  std::string one_line() const;
};

/// Mean squared error of the latent mean on `validation`.
double validation_mse(const FittedGp& model, const TrainingSet& validation);

/// Fits with `backend`; attempt k uses seed options.seed + k (a fresh subsample and fresh restarts).
/// Without a previous learner, the first attempt is accepted. Throws std::invalid_argument when the
/// validation set is empty or its dimension differs.
FitResult fit_with_resampling(const GpBackend& backend, const TrainingSet& data, const TrainingSet& validation,
                              const FittedGp* previous, const FitOptions& options,
                              const ResampleOptions& resample, ResampleReport* report = nullptr);

}  // namespace gpilqg::gp
