#pragma once
/// @file kernel.hpp
/// The ARD squared-exponential kernel in GPML's convention (GPML book eq. 5.2, covSEard):
///
///   k(a, b) = sf^2 exp(-0.5 sum_d (a_d - b_d)^2 / l_d^2)
///
/// The paper (GP-ILQG, section "Gaussian Process with the Simulator as a Mean Function") writes
///
///   k(z_i, z_j) = sf^2 exp(-(z_i - z_j)' Lambda^-1 (z_i - z_j))
///
/// without the 1/2. Matching exponents, r^2 / Lambda_dd = r^2 / (2 l_d^2), so the two are the same kernel
/// with Lambda_dd = 2 l_d^2, i.e. l_d = sqrt(Lambda_dd / 2) = 1 / sqrt(2 W_dd) for W = Lambda^-1
/// (as tests/reference/gp_oracle/README.md writes it).
///
/// Derivatives used by the backends (r_d = a_d - b_d):
///   dk/d log l_d = k r_d^2 / l_d^2,   dk/d log sf = 2 k,   dk/da_d = -k r_d / l_d^2.

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::gp {

class ArdSquaredExponential {
 public:
  /// Throws std::invalid_argument when an entry is not finite.
  ArdSquaredExponential(const VectorCRef& log_lengthscales, double log_signal_std);
  explicit ArdSquaredExponential(const Hyperparameters& hyperparameters);

  int input_dim() const { return static_cast<int>(inverse_squared_lengthscales_.size()); }
  double signal_variance() const { return signal_variance_; }
  /// 1 / l_d^2 (D entries).
  const Vector& inverse_squared_lengthscales() const { return inverse_squared_lengthscales_; }

  /// k(a, b).
  double operator()(const VectorCRef& a, const VectorCRef& b) const;
  /// K(X, X) (N x N), X with one point per row; no noise term.
  Matrix covariance(const MatrixCRef& points) const;
  /// K(A, B) (rows(A) x rows(B)).
  Matrix cross_covariance(const MatrixCRef& a, const MatrixCRef& b) const;
  /// k(X, z) into `out` (N); out must have N entries.
  void cross_covariance(const MatrixCRef& points, const VectorCRef& z, VectorRef out) const;

 private:
  Vector inverse_squared_lengthscales_;
  double signal_variance_;
};

}  // namespace gpilqg::gp
