#pragma once
/// @file sparse_linalg.hpp
/// Internal linear algebra shared by the FITC and SSGP backends (not installed): the squared
/// exponential kernel on length-scale-scaled inputs, and a Cholesky factorisation that escalates
/// the jitter along a JitterSchedule when a matrix is not numerically positive definite.

#include <utility>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp::sparse_detail {

/// Outcome of a Cholesky factorisation with escalating jitter.
struct CholeskyOutcome {
  FactorStatus status = FactorStatus::Failed;
  double extra_jitter = 0.0;  ///< absolute jitter added on top of the base (0 when status == Ok)
};

/// Factorises S + (base + e) I = L L' (lower L written into `factor`) with the smallest e in
/// {0, first * scale, first * scale * growth, ..., <= last * scale} (JitterSchedule) that gives a
/// factor with a finite diagonal whose squared entries (the pivots) all exceed 16 eps times the
/// largest diagonal entry (a smaller pivot is rounding noise: numerically singular). `base` is a jitter that
/// is part of the model (FITC's snu2), `scale` the reference magnitude of the diagonal. S is read from the
/// lower triangle of `matrix`, which is left unchanged. Never throws on numerical trouble.
CholeskyOutcome cholesky_with_jitter(const Matrix& matrix, double base, double scale,
                                     const JitterSchedule& schedule, Matrix& factor);

/// The squared exponential kernel k(a, b) = sf2 exp(-0.5 |a - b|^2) on inputs already divided by
/// the length-scales (GPML covSEard). Writes the rows(A) x rows(B) matrix into K (already of that
/// size, e.g. a block of columns); computes the squared distances as |a|^2 + |b|^2 - 2 a.b (one
/// matrix product), clamped at 0.
void se_cross_covariance(const MatrixCRef& A, const MatrixCRef& B, double sf2, Eigen::Ref<Matrix> K);

/// Columns [begin, end) of the `worker`-th of `workers` equal shares of n columns.
inline std::pair<Eigen::Index, Eigen::Index> share(Eigen::Index n, int worker, int workers) {
  return {n * worker / workers, n * (worker + 1) / workers};
}

/// Training points per worker below which a second thread does not pay for its start-up.
inline constexpr Eigen::Index kPointsPerWorker = 500;

/// The same for one set of points against itself, with distances summed coordinate by coordinate
/// (exact zero on the diagonal, symmetric to the last bit).
void se_covariance(const MatrixCRef& A, double sf2, Matrix& K);

/// Status of a factorisation and the jitter to report, merged over several factorisations.
inline void merge(const CholeskyOutcome& outcome, FactorStatus& status, double& jitter) {
  if (outcome.status == FactorStatus::Failed)
    status = FactorStatus::Failed;
  else if (outcome.status == FactorStatus::JitterAdded && status == FactorStatus::Ok)
    status = FactorStatus::JitterAdded;
  jitter = std::max(jitter, outcome.extra_jitter);
}

/// log(2 pi).
inline constexpr double kLog2Pi = 1.8378770664093454836;

/// The contract of a failed NLML evaluation: +infinity, status Failed (never NaN).
NlmlEvaluation failed_evaluation(double jitter = 0.0);

/// The checks both sparse likelihoods make on construction; throws std::invalid_argument with the
/// message prefixed by `who` ("FitcLikelihood"): empty X, |r| != rows of X, non-finite data,
/// `count` < 1 (the number of `what`: pseudo-inputs, spectral points), threads < 1.
void validate_likelihood_inputs(const char* who, const MatrixCRef& X, const VectorCRef& r, int count,
                                const char* what, int threads);

}  // namespace gpilqg::gp::sparse_detail
