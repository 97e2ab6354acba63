#pragma once
/// @file exact_gp.hpp
/// Exact GP regression on a uniform random subsample of the data (the paper keeps all observations
/// and "uniformly sub-sample[s] 300 data points at each iteration"), GPML book algorithm 2.1.
///
/// With K = K(X, X) + sn^2 I = L L' (Cholesky), alpha = K^-1 y:
///   mean(z)     = k(z)' alpha                                         (GPML eq. 2.25)
///   variance(z) = sf^2 - k(z)' K^-1 k(z)                              (GPML eq. 2.26)
///   nlml        = 0.5 y' alpha + sum_i log L_ii + N/2 log(2 pi)       (GPML eq. 2.30)
///   d nlml / d theta_j = -0.5 tr((alpha alpha' - K^-1) dK/dtheta_j)   (GPML eq. 5.9)
/// Prediction caches alpha and L^-1 (N <= 3000), so one query costs O(N D) for the mean and two
/// triangular matrix-vector products (N^2 flops) more for the variance and its gradient.

#include <limits>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

struct ExactGpOptions {
  /// Use all points: set max_training_points to this.
  static constexpr int kAllPoints = std::numeric_limits<int>::max();
  /// Size of the uniform subsample (the paper's 300); kAllPoints for the full exact GP.
  int max_training_points = 300;
  /// Threads for the O(N^3) linear algebra of one NLML evaluation or conditioning (Cholesky, L^-1,
  /// K^-1; used from N = 384 on). 1 by default because the residual model already fits its outputs
  /// in parallel; 2 speeds up a single large fit on the 2-core machine.
  int threads = 1;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

class ExactGpBackend final : public GpBackend {
 public:
  explicit ExactGpBackend(ExactGpOptions options = {});
  std::string_view name() const override { return "exact"; }
  bool takes_known_noise() const override { return true; }
  const ExactGpOptions& options() const { return options_; }

  TrainingSet select_training_points(const TrainingSet& data, std::uint64_t seed) const override;
  std::unique_ptr<MarginalLikelihoodObjective> objective(const TrainingSet& data,
                                                         const FitOptions& options) const override;
  std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters,
                                      const JitterSchedule& jitter = {}) const override;

 private:
  ExactGpOptions options_;
};

}  // namespace gpilqg::gp
