#include "dense_cholesky.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace gpilqg::gp::detail {

namespace {

constexpr Eigen::Index kBaseSize = 48;        // below this, the unblocked column algorithms
constexpr Eigen::Index kParallelSize = 384;   // below this, one thread (thread start-up would dominate)

using Lower = Eigen::TriangularView<Eigen::Ref<Matrix>, Eigen::Lower>;

/// dtrti2 (lower, non-unit): column j from the right, A(j+1:, j) = -A(j,j)^-1 times the product with
/// the already inverted trailing block.
void invert_lower_unblocked(Eigen::Ref<Matrix> a) {
  const Eigen::Index n = a.rows();
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kBaseSize, 1> tmp(n);
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    a(j, j) = 1.0 / a(j, j);
    const Eigen::Index m = n - j - 1;
    if (m > 0) {
      auto column = a.col(j).tail(m);
      tmp.head(m).noalias() = a.bottomRightCorner(m, m).triangularView<Eigen::Lower>() * column;
      column = -a(j, j) * tmp.head(m);
    }
  }
}

/// dlauu2 (lower): row i of the result from the rows below it.
void lower_gram_unblocked(Eigen::Ref<Matrix> a) {
  const Eigen::Index n = a.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double aii = a(i, i);
    const Eigen::Index below = n - i - 1;
    if (below > 0) {
      a(i, i) = a.col(i).tail(n - i).squaredNorm();
      // A(i, 0:i) = aii A(i, 0:i) + A(i+1:, i)' A(i+1:, 0:i)
      for (Eigen::Index k = 0; k < i; ++k) a(i, k) = aii * a(i, k) + a.col(i).tail(below).dot(a.col(k).tail(below));
    } else {
      a.row(i).head(i + 1) *= aii;
    }
  }
}

bool diagonal_is_positive(const Eigen::Ref<Matrix>& a) {
  const auto diagonal = a.diagonal().array();
  return diagonal.allFinite() && (diagonal > 0.0).all();
}

}  // namespace

bool cholesky_in_place(Eigen::Ref<Matrix> a, int threads) {
  const Eigen::Index n = a.rows();
  if (threads < 2 || n < kParallelSize) {
    Eigen::LLT<Eigen::Ref<Matrix>, Eigen::Lower> llt(a);
    return llt.info() == Eigen::Success && diagonal_is_positive(a);
  }
  // [A11 .; A21 A22] = [L11 0; L21 L22][L11' L21'; 0 L22']:
  //   L11 = chol(A11),  L21 = A21 L11^-T,  L22 = chol(A22 - L21 L21').
  const Eigen::Index n1 = n / 2, n2 = n - n1, half = n2 / 2;
  if (!cholesky_in_place(a.topLeftCorner(n1, n1), threads)) return false;
  auto l11 = a.topLeftCorner(n1, n1).triangularView<Eigen::Lower>();
  auto a21 = a.bottomLeftCorner(n2, n1);
  run_pair(
      true, [&] { l11.adjoint().solveInPlace<Eigen::OnTheRight>(a21.topRows(half)); },
      [&] { l11.adjoint().solveInPlace<Eigen::OnTheRight>(a21.bottomRows(n2 - half)); });
  auto a22 = a.bottomRightCorner(n2, n2);
  const auto x1 = a21.topRows(half);
  const auto x2 = a21.bottomRows(n2 - half);
  run_pair(
      true,
      [&] {
        a22.topLeftCorner(half, half).selfadjointView<Eigen::Lower>().rankUpdate(x1, -1.0);
        a22.bottomRightCorner(n2 - half, n2 - half).selfadjointView<Eigen::Lower>().rankUpdate(x2, -1.0);
      },
      [&] { a22.bottomLeftCorner(n2 - half, half).noalias() -= x2 * x1.transpose(); });
  return cholesky_in_place(a22, threads);
}

FactorOutcome cholesky_with_jitter(Eigen::Index n, const std::function<void(Matrix&)>& fill_kernel_lower,
                                   double mean_kernel_diagonal, double noise_variance,
                                   const JitterSchedule& schedule, Matrix& factor, int threads) {
  if (factor.rows() != n || factor.cols() != n) factor.resize(n, n);
  fill_kernel_lower(factor);
  factor.diagonal().array() += noise_variance;
  if (cholesky_in_place(factor, threads)) return {FactorStatus::Ok, 0.0};
  const double scale = std::max(mean_kernel_diagonal + noise_variance, 1e-300);
  for (double relative = schedule.first; relative <= schedule.last * (1.0 + 1e-12); relative *= schedule.growth) {
    const double jitter = relative * scale;
    fill_kernel_lower(factor);
    factor.diagonal().array() += noise_variance + jitter;
    if (cholesky_in_place(factor, threads)) return {FactorStatus::JitterAdded, jitter};
  }
  return {FactorStatus::Failed, schedule.last * scale};
}

FactorOutcome cholesky_with_jitter(const Matrix& kernel, double noise_variance, const JitterSchedule& schedule,
                                   Matrix& factor, int threads) {
  const Eigen::Index n = kernel.rows();
  auto copy_lower = [&kernel, n](Matrix& target) {
    for (Eigen::Index j = 0; j < n; ++j) target.col(j).tail(n - j) = kernel.col(j).tail(n - j);
  };
  return cholesky_with_jitter(n, copy_lower, kernel.diagonal().mean(), noise_variance, schedule, factor, threads);
}

void invert_lower_triangular(Eigen::Ref<Matrix> a, int threads) {
  const Eigen::Index n = a.rows();
  if (n <= kBaseSize) {
    invert_lower_unblocked(a);
    return;
  }
  // [A11 0; A21 A22]^-1 = [A11^-1 0; -A22^-1 A21 A11^-1, A22^-1]
  const Eigen::Index n1 = n / 2, n2 = n - n1;
  const bool parallel = threads > 1 && n >= kParallelSize;
  const int inner = parallel ? std::max(1, threads / 2) : threads;
  run_pair(
      parallel, [&] { invert_lower_triangular(a.topLeftCorner(n1, n1), inner); },
      [&] { invert_lower_triangular(a.bottomRightCorner(n2, n2), inner); });
  auto a21 = a.bottomLeftCorner(n2, n1);
  Matrix tmp(n2, n1);
  const Eigen::Index rows = n2 / 2, cols = n1 / 2;
  auto inv11 = a.topLeftCorner(n1, n1).triangularView<Eigen::Lower>();
  auto inv22 = a.bottomRightCorner(n2, n2).triangularView<Eigen::Lower>();
  run_pair(
      parallel, [&] { tmp.topRows(rows).noalias() = a21.topRows(rows) * inv11; },
      [&] { tmp.bottomRows(n2 - rows).noalias() = a21.bottomRows(n2 - rows) * inv11; });
  run_pair(
      parallel, [&] { a21.leftCols(cols).noalias() = -(inv22 * tmp.leftCols(cols)); },
      [&] { a21.rightCols(n1 - cols).noalias() = -(inv22 * tmp.rightCols(n1 - cols)); });
}

void lower_gram(Eigen::Ref<Matrix> a, int threads) {
  const Eigen::Index n = a.rows();
  if (n <= kBaseSize) {
    lower_gram_unblocked(a);
    return;
  }
  // M = [M11 0; M21 M22]:  M'M = [M11'M11 + M21'M21, .; M22'M21, M22'M22]
  const Eigen::Index n1 = n / 2, n2 = n - n1, cols = n1 / 2;
  const bool parallel = threads > 1 && n >= kParallelSize;
  const int inner = parallel ? std::max(1, threads / 2) : threads;
  auto m21 = a.bottomLeftCorner(n2, n1);
  auto m22 = a.bottomRightCorner(n2, n2).triangularView<Eigen::Lower>();
  Matrix product(n2, n1);  // M22' M21, computed while M22 and M21 still hold their inputs
  run_pair(
      parallel, [&] { product.leftCols(cols).noalias() = m22.transpose() * m21.leftCols(cols); },
      [&] { product.rightCols(n1 - cols).noalias() = m22.transpose() * m21.rightCols(n1 - cols); });
  run_pair(
      parallel,
      [&] {
        lower_gram(a.topLeftCorner(n1, n1), inner);
        a.topLeftCorner(n1, n1).selfadjointView<Eigen::Lower>().rankUpdate(m21.transpose());
      },
      [&] { lower_gram(a.bottomRightCorner(n2, n2), inner); });
  m21 = product;
}

void inverse_from_cholesky(Eigen::Ref<Matrix> factor, int threads) {
  invert_lower_triangular(factor, threads);
  lower_gram(factor, threads);
}

void symmetrize_from_lower(Matrix& m) { m.triangularView<Eigen::StrictlyUpper>() = m.transpose(); }

}  // namespace gpilqg::gp::detail
