#pragma once
/// @file training_set.hpp
/// Regression data for one GP output: N inputs (rows of an N x D matrix, as GPML and the benchmark
/// files store them) and N targets. The GP layer is zero-mean: targets are residuals, any prior mean
/// (the simulator, or the oracle's sum sin(x_d)) has already been subtracted (see prior_mean.hpp).

#include <cstdint>
#include <string_view>
#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp {

struct TrainingSet {
  Matrix inputs;   ///< N x D, one point per row
  Vector targets;  ///< N
  /// N, or empty: a noise variance of each target known before the fit (for a residual GP, the noise
  /// the model itself predicts at that point). The likelihood is then y ~ N(0, K + diag(sn^2 + v_i)):
  /// v_i is known and fixed, sn^2 the learned homoscedastic part (GPyTorch's
  /// FixedNoiseGaussianLikelihood with learn_additional_noise; scikit-learn's per-sample alpha with a
  /// WhiteKernel). Taken by the backends whose GpBackend::takes_known_noise() is true; the others
  /// refuse it (refuse_known_noise).
  Vector noise_variance = Vector();

  int size() const { return static_cast<int>(inputs.rows()); }
  int input_dim() const { return static_cast<int>(inputs.cols()); }

  /// The rows `indices` (in that order).
  TrainingSet subset(const std::vector<int>& indices) const;
};

/// Throws std::invalid_argument, with `who` and the offending values in the message, when the data
/// cannot be regressed on: inputs/targets size mismatch, no input dimensions, fewer points than
/// inputs (N < D), a non-finite input or target (naming row and column), constant targets, or known
/// noise variances (noise_variance) that are not N finite values >= 0.
void validate_training_set(const TrainingSet& data, std::string_view who);

/// Throws std::invalid_argument naming `backend` when `data` has known noise variances, which that
/// backend does not take.
void refuse_known_noise(const TrainingSet& data, std::string_view backend);

/// `count` distinct row indices drawn uniformly without replacement from [0, size), sorted; all rows
/// when count >= size. Deterministic for a given seed.
std::vector<int> uniform_subsample(int size, int count, std::uint64_t seed);

}  // namespace gpilqg::gp
