#pragma once
/// @file shared_prediction.hpp
/// Prediction of several exact GPs conditioned on the same training inputs X (N x D), as the residual
/// model's outputs are (one GP per state, one shared subsample), sharing what depends only on X and
/// the query z:
///
///  - the squared differences (x_id - z_d)^2 (N x D) are formed once per query for all n outputs, and
///    output a's cross-covariance is k_a = sf_a^2 exp(-1/2 sum_d w_ad (x_id - z_d)^2) from them;
///  - the n vectors k_a are kept in the caller's Cache for the last query, so the DDP engine's two
///    calls at the same (x, u) (step for the mean, uncertainty for the variance, in either order, with
///    the same workspace) form them once, and the variance no longer recomputes the mean.
///
/// Each output's per-output work is ExactPredictor's (exact_prediction.hpp), so the results are those
/// of FittedGp::predict to the bit. What stays per output is the variance's triangular products with
/// its own L^-1 (N^2 each, the bulk of the cost at N = 300; see the README's GP benchmarks).
///
/// Thread safety: the object is immutable; the per-query cache belongs to the caller (one per thread)
/// and is keyed by a process-unique id of the object and the bits of z, so a cache handed to another
/// model never returns its entries. After warm-up (one query at these sizes) nothing allocates.

#include <cstdint>
#include <memory>
#include <vector>

#include "exact_prediction.hpp"

namespace gpilqg::gp::detail {

class SharedExactPrediction {
 public:
  /// The caller's cache: k_a (column a of `cross`) at the last query z.
  struct Cache {
    std::uint64_t id = 0;  // 0: empty (ids start at 1)
    Vector z;
    Matrix squared;  // (X - 1 z').^2, N x D
    Matrix cross;    // k_a in column a, N x n
    Vector gradient, weighted, scratch;
  };

  /// The shared predictor of `outputs`, or null when they are not all exact GPs with identical
  /// training inputs (then each output predicts on its own).
  static std::shared_ptr<const SharedExactPrediction> make(
      const std::vector<std::shared_ptr<const FittedGp>>& outputs);

  /// Means of all outputs at z (mean: n), and d mean_a / dz as row a of `gradient` (n x D) when not null.
  void means(const VectorCRef& z, Vector& mean, Matrix* gradient, Cache& cache) const;
  /// Latent variances (clamped at 0) of all outputs at z, and their gradients as rows when not null.
  void variances(const VectorCRef& z, Vector& variance, Matrix* gradient, Cache& cache) const;

 private:
  SharedExactPrediction(std::vector<std::shared_ptr<const FittedGp>> outputs,
                        std::vector<const ExactPredictor*> predictors);
  /// `cache`, holding k_a (column a) at z.
  Cache& at(const VectorCRef& z, Cache& cache) const;
  /// values(a) = stage(predictor a, cache, k_a, gradient buffer or null) for every output at z, and the
  /// gradient buffer into row a of `gradient` when not null.
  template <class Stage>
  void each_output(const VectorCRef& z, Vector& values, Matrix* gradient, Cache& cache, Stage&& stage) const;

  std::vector<std::shared_ptr<const FittedGp>> outputs_;  // keeps the predictors alive
  std::vector<const ExactPredictor*> predictors_;
  std::uint64_t id_;
};

}  // namespace gpilqg::gp::detail
