#include "sparse_linalg.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gpilqg::gp::sparse_detail {

namespace {

/// A pivot (squared diagonal entry of the factor) below this fraction of the largest diagonal entry
/// of the matrix means numerical rank deficiency (e.g. two identical points): the factor would be
/// dominated by rounding, so it counts as a failure and the jitter is escalated.
constexpr double kPivotFloor = 16.0 * std::numeric_limits<double>::epsilon();

/// In-place Cholesky of the lower triangle of `factor` plus `jitter` on its diagonal.
bool try_factor(const Matrix& matrix, double jitter, Matrix& factor) {
  const Eigen::Index n = matrix.rows();
  factor.resize(n, n);
  factor.triangularView<Eigen::Lower>() = matrix.triangularView<Eigen::Lower>();
  factor.diagonal().array() += jitter;
  const double largest = factor.diagonal().cwiseAbs().maxCoeff();
  Eigen::LLT<Eigen::Ref<Matrix>, Eigen::Lower> llt(factor);
  if (llt.info() != Eigen::Success) return false;
  const auto d = factor.diagonal().array();
  if (!d.allFinite() || !(d.square() > kPivotFloor * largest).all()) return false;
  factor.triangularView<Eigen::StrictlyUpper>().setZero();
  return true;
}

}  // namespace

CholeskyOutcome cholesky_with_jitter(const Matrix& matrix, double base, double scale,
                                     const JitterSchedule& schedule, Matrix& factor) {
  CholeskyOutcome outcome;
  if (try_factor(matrix, base, factor)) {
    outcome.status = FactorStatus::Ok;
    return outcome;
  }
  const double reference = std::isfinite(scale) && scale > 0.0 ? scale : 1.0;
  const double last = schedule.last * reference * (1.0 + 1e-12);
  for (double extra = schedule.first * reference; extra <= last; extra *= schedule.growth) {
    if (try_factor(matrix, base + extra, factor)) {
      outcome.status = FactorStatus::JitterAdded;
      outcome.extra_jitter = extra;
      return outcome;
    }
  }
  outcome.status = FactorStatus::Failed;
  return outcome;
}

void se_cross_covariance(const MatrixCRef& A, const MatrixCRef& B, double sf2, Eigen::Ref<Matrix> K) {
  K.noalias() = A * B.transpose();
  const Vector a2 = A.rowwise().squaredNorm();
  const Vector b2 = B.rowwise().squaredNorm();
  // sf2 exp(-0.5 max(|a|^2 + |b|^2 - 2 a.b, 0)), column by column for cache locality.
  for (Eigen::Index j = 0; j < K.cols(); ++j) {
    auto col = K.col(j).array();
    col = sf2 * (-0.5 * (a2.array() + b2(j) - 2.0 * col).max(0.0)).exp();
  }
}

void se_covariance(const MatrixCRef& A, double sf2, Matrix& K) {
  const Eigen::Index n = A.rows();
  K.resize(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    K(j, j) = sf2;
    for (Eigen::Index i = j + 1; i < n; ++i) {
      const double d2 = (A.row(i) - A.row(j)).squaredNorm();
      K(i, j) = K(j, i) = sf2 * std::exp(-0.5 * d2);
    }
  }
}

NlmlEvaluation failed_evaluation(double jitter) {
  NlmlEvaluation e;
  e.value = std::numeric_limits<double>::infinity();
  e.status = FactorStatus::Failed;
  e.jitter = jitter;
  return e;
}

void validate_likelihood_inputs(const char* who, const MatrixCRef& X, const VectorCRef& r, int count,
                                const char* what, int threads) {
  auto require = [who](bool condition, const std::string& message) {
    if (!condition) throw std::invalid_argument(std::string(who) + ": " + message);
  };
  require(X.rows() > 0 && X.cols() > 0,
          "no training inputs (X is " + std::to_string(X.rows()) + " x " + std::to_string(X.cols()) + ")");
  require(r.size() == X.rows(), "X has " + std::to_string(X.rows()) + " rows but there are " +
                                    std::to_string(r.size()) + " targets");
  require(X.allFinite() && r.allFinite(), "training data contain non-finite values");
  require(count >= 1, std::string("the number of ") + what + " must be >= 1, got " + std::to_string(count));
  require(threads >= 1, "threads must be >= 1, got " + std::to_string(threads));
}

}  // namespace gpilqg::gp::sparse_detail
