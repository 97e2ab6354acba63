#include "gpilqg/gp/kernel.hpp"

#include <cmath>
#include <stdexcept>

namespace gpilqg::gp {

ArdSquaredExponential::ArdSquaredExponential(const VectorCRef& log_lengthscales, double log_signal_std) {
  if (log_lengthscales.size() == 0 || !log_lengthscales.allFinite() || !std::isfinite(log_signal_std))
    throw std::invalid_argument("ArdSquaredExponential: expected at least one finite log length-scale "
                                "and a finite log signal std");
  inverse_squared_lengthscales_ = (-2.0 * log_lengthscales.array()).exp().matrix();
  signal_variance_ = std::exp(2.0 * log_signal_std);
}

ArdSquaredExponential::ArdSquaredExponential(const Hyperparameters& h)
    : ArdSquaredExponential(h.log_lengthscales, h.log_signal_std) {}

double ArdSquaredExponential::operator()(const VectorCRef& a, const VectorCRef& b) const {
  return signal_variance_ *
         std::exp(-0.5 * ((a - b).array().square() * inverse_squared_lengthscales_.array()).sum());
}

Matrix ArdSquaredExponential::cross_covariance(const MatrixCRef& a, const MatrixCRef& b) const {
  if (a.cols() != input_dim() || b.cols() != input_dim())
    throw std::invalid_argument("ArdSquaredExponential::cross_covariance: inputs must have D columns");
  // Scaled points s = x / l: the exponent is -0.5 |s_a - s_b|^2.
  const Vector inv_l = inverse_squared_lengthscales_.array().sqrt();
  const Matrix sa = a * inv_l.asDiagonal();
  const Matrix sb = b * inv_l.asDiagonal();
  Matrix k(a.rows(), b.rows());
  for (Eigen::Index j = 0; j < b.rows(); ++j)
    for (Eigen::Index i = 0; i < a.rows(); ++i) k(i, j) = (sa.row(i) - sb.row(j)).squaredNorm();
  return (signal_variance_ * (-0.5 * k.array()).exp()).matrix();
}

Matrix ArdSquaredExponential::covariance(const MatrixCRef& points) const {
  return cross_covariance(points, points);
}

void ArdSquaredExponential::cross_covariance(const MatrixCRef& points, const VectorCRef& z, VectorRef out) const {
  if (points.cols() != input_dim() || z.size() != input_dim() || out.size() != points.rows())
    throw std::invalid_argument("ArdSquaredExponential::cross_covariance: size mismatch");
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    out(i) = ((points.row(i).transpose() - z).array().square() * inverse_squared_lengthscales_.array()).sum();
  out = (signal_variance_ * (-0.5 * out.array()).exp()).matrix();
}

}  // namespace gpilqg::gp
