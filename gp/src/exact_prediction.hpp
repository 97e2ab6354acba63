#pragma once
/// @file exact_prediction.hpp
/// The conditioned exact GP's prediction in stages, so that outputs on the same training inputs can
/// share the work that depends only on the inputs (shared_prediction.hpp). With r_i = x_i - z (x_i
/// row i of X, N x D), w_d = 1 / l_d^2 and the cached alpha = K^-1 y and L^-1 (or L):
///
///   cross     k_i = sf^2 exp(-1/2 sum_d w_d r_id^2)                         O(N D) + N exp
///   mean      m = k' alpha,   d m / dz_d = w_d sum_i alpha_i k_i r_id          O(N) (+ O(N D))
///   variance  v = sf^2 - |L^-1 k|^2,  d v / dz_d = -2 w_d sum_i u_i k_i r_id,  u = K^-1 k = L^-T L^-1 k
///                                                                            N^2 (+ N^2 + O(N D))
/// (GPML eqs. 2.25, 2.26, algorithm 2.1). The r_id^2 depend on z and X only: outputs sharing X share
/// them. The sums use sum_i c_i r_id = x_d' c - z_d sum_i c_i, so gradients read X, not r.

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp::detail {

class ExactPredictor {
 public:
  ExactPredictor() = default;
  ExactPredictor(const Matrix* inputs, Vector inverse_squared_lengthscales, double signal_variance)
      : inputs_(inputs), w_(std::move(inverse_squared_lengthscales)), sf2_(signal_variance) {}

  /// The cached weights: alpha and either L^-1 (lower, zero above) or L.
  void set_weights(Vector alpha, Matrix inverse_factor, Matrix factor) {
    alpha_ = std::move(alpha);
    inverse_factor_ = std::move(inverse_factor);
    factor_ = std::move(factor);
  }

  const Matrix& inputs() const { return *inputs_; }
  const Vector& inverse_squared_lengthscales() const { return w_; }
  double signal_variance() const { return sf2_; }
  const Vector& alpha() const { return alpha_; }
  const Matrix& inverse_factor() const { return inverse_factor_; }
  const Matrix& factor() const { return factor_; }

  /// (X - 1 z').^2 into `squared` (N x D): the part of k every output on X shares.
  static void squared_differences(const Matrix& inputs, const VectorCRef& z, Matrix& squared);
  /// k (N entries, already sized) at z; from `squared` (N x D, squared_differences of the same X and
  /// z) when not null, else computed column by column. Both give the same bits: the same terms summed
  /// in the same order.
  void cross(const VectorCRef& z, const Matrix* squared, Eigen::Ref<Vector> k) const;
  /// The mean, and its gradient when `gradient` is not null (resized to D). `scratch`: N.
  double mean(const VectorCRef& z, const VectorCRef& k, Vector* gradient, Vector& scratch) const;
  /// The latent variance clamped at 0, and its gradient when `gradient` is not null (resized to D).
  /// `weighted`, `scratch`: N.
  double variance(const VectorCRef& z, const VectorCRef& k, Vector* gradient, Vector& weighted,
                  Vector& scratch) const;

 private:
  const Matrix* inputs_ = nullptr;  // X of the owning model (stable: the model is not copied or moved)
  Vector w_;
  double sf2_ = 0.0;
  Vector alpha_;
  Matrix inverse_factor_;  // L^-1 (lower, zero above) when cached
  Matrix factor_;          // L = chol(K) when L^-1 is not cached
};

/// The exact predictor of `gp` when it is the exact backend's fitted model, else nullptr.
const ExactPredictor* exact_predictor(const FittedGp& gp);

}  // namespace gpilqg::gp::detail
