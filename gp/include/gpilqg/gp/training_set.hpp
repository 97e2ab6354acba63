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

  int size() const { return static_cast<int>(inputs.rows()); }
  int input_dim() const { return static_cast<int>(inputs.cols()); }

  /// The rows `indices` (in that order).
  TrainingSet subset(const std::vector<int>& indices) const;
};

/// Throws std::invalid_argument, with `who` and the offending values in the message, when the data
/// cannot be regressed on: inputs/targets size mismatch, no input dimensions, fewer points than
/// inputs (N < D), a non-finite input or target (naming row and column), or constant targets.
void validate_training_set(const TrainingSet& data, std::string_view who);

/// `count` distinct row indices drawn uniformly without replacement from [0, size), sorted; all rows
/// when count >= size. Deterministic for a given seed.
std::vector<int> uniform_subsample(int size, int count, std::uint64_t seed);

}  // namespace gpilqg::gp
