#pragma once
/// @file compact_kernel.hpp
/// Internal: Wendland's phi_{D,1} with ARD length-scales (compact.hpp has the maths), evaluated on
/// squared scaled distances r^2 = sum_d (a_d - b_d)^2 / l_d^2.

#include <cmath>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::gp::detail {

class WendlandKernel {
 public:
  /// From [log l (D); log sf; ...]; throws std::invalid_argument when the vector is too short.
  WendlandKernel(const VectorCRef& parameters, int input_dim);

  int input_dim() const { return static_cast<int>(inverse_lengthscales_.size()); }
  /// j = floor(D / 2) + 2, the smallest exponent for which phi_{D,1} is positive definite on R^D.
  int exponent() const { return exponent_; }
  double signal_variance() const { return signal_variance_; }
  /// 1 / l_d (D).
  const Vector& inverse_lengthscales() const { return inverse_lengthscales_; }
  /// 1 / l_d^2 (D).
  const Vector& inverse_squared_lengthscales() const { return inverse_squared_lengthscales_; }

  /// k at squared scaled distance r2: sf^2 (1 - r)^(j+1) ((j+1) r + 1) for r < 1, else 0.
  double value(double r2) const {
    if (!(r2 < 1.0)) return 0.0;
    const double r = std::sqrt(r2);
    const double s = power(1.0 - r, exponent_);
    return signal_variance_ * s * (1.0 - r) * ((exponent_ + 1) * r + 1.0);
  }
  /// g(r) = -(1/r) dk/dr = sf^2 (j+1)(j+2) (1 - r)^j for r < 1, else 0.
  double slope(double r2) const {
    if (!(r2 < 1.0)) return 0.0;
    return signal_variance_ * (exponent_ + 1) * (exponent_ + 2) * power(1.0 - std::sqrt(r2), exponent_);
  }
  /// Squared scaled distance between row `row` of `points` (N x D, column-major) and z.
  double squared_distance(const Matrix& points, Eigen::Index row, const VectorCRef& z) const {
    double r2 = 0.0;
    for (Eigen::Index d = 0; d < points.cols(); ++d) {
      const double t = (points(row, d) - z(d)) * inverse_lengthscales_(d);
      r2 += t * t;
    }
    return r2;
  }

 private:
  static double power(double base, int exponent) {
    double result = 1.0;
    for (int i = 0; i < exponent; ++i) result *= base;
    return result;
  }
  Vector inverse_lengthscales_;
  Vector inverse_squared_lengthscales_;
  double signal_variance_ = 1.0;
  int exponent_ = 2;
};

/// The common factor c for the data-driven start l_d = c s_d (s_d the input spreads of
/// initial_hyperparameters): the median over up to 512 evenly spaced points of the distance, in the
/// s-scaled metric, to their `neighbours`-th nearest other point (so a point has about `neighbours`
/// points within the support). Brute force, O(min(N, 512) N D).
double support_scale_for_neighbours(const Matrix& inputs, const Vector& spreads, int neighbours);

}  // namespace gpilqg::gp::detail
