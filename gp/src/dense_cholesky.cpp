#include "dense_cholesky.hpp"

#include "blas_lapack.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <cmath>

namespace gpilqg::gp::detail {

namespace {

/// Below this order one thread does the whole job (thread start-up would dominate); above it, the
/// blocks of the recursion are split over two threads. The leaves are single-threaded LAPACK/BLAS
/// calls (blas_lapack.hpp).
constexpr Eigen::Index kParallelSize = 384;

using blas::Side;
using blas::Transpose;

}  // namespace

bool cholesky_in_place(Eigen::Ref<Matrix> a, int threads) {
  const Eigen::Index n = a.rows();
  if (threads < 2 || n < kParallelSize) return blas::cholesky_lower(a);
  // [A11 .; A21 A22] = [L11 0; L21 L22][L11' L21'; 0 L22']:
  //   L11 = chol(A11),  L21 = A21 L11^-T,  L22 = chol(A22 - L21 L21').
  const Eigen::Index n1 = n / 2, n2 = n - n1, half = n2 / 2;
  if (!cholesky_in_place(a.topLeftCorner(n1, n1), threads)) return false;
  const auto l11 = a.topLeftCorner(n1, n1);
  auto a21 = a.bottomLeftCorner(n2, n1);
  run_pair(
      true, [&] { blas::solve_lower(Side::Right, Transpose::Yes, l11, a21.topRows(half)); },
      [&] { blas::solve_lower(Side::Right, Transpose::Yes, l11, a21.bottomRows(n2 - half)); });
  auto a22 = a.bottomRightCorner(n2, n2);
  const auto x1 = a21.topRows(half);
  const auto x2 = a21.bottomRows(n2 - half);
  run_pair(
      true,
      [&] {
        blas::rank_update_lower(-1.0, x1, Transpose::No, 1.0, a22.topLeftCorner(half, half));
        blas::rank_update_lower(-1.0, x2, Transpose::No, 1.0, a22.bottomRightCorner(n2 - half, n2 - half));
      },
      [&] { blas::multiply(-1.0, x2, Transpose::No, x1, Transpose::Yes, 1.0, a22.bottomLeftCorner(n2 - half, half)); });
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
  if (threads < 2 || n < kParallelSize) {
    blas::invert_lower(a);
    return;
  }
  // [A11 0; A21 A22]^-1 = [A11^-1 0; -A22^-1 A21 A11^-1, A22^-1]
  const Eigen::Index n1 = n / 2, n2 = n - n1;
  const int inner = std::max(1, threads / 2);
  run_pair(
      true, [&] { invert_lower_triangular(a.topLeftCorner(n1, n1), inner); },
      [&] { invert_lower_triangular(a.bottomRightCorner(n2, n2), inner); });
  auto a21 = a.bottomLeftCorner(n2, n1);
  const Eigen::Index rows = n2 / 2, cols = n1 / 2;
  const auto inv11 = a.topLeftCorner(n1, n1);
  const auto inv22 = a.bottomRightCorner(n2, n2);
  // A21 := A21 A11^-1 by row blocks, then A21 := -A22^-1 A21 by column blocks.
  run_pair(
      true, [&] { blas::multiply_lower(Side::Right, Transpose::No, inv11, a21.topRows(rows)); },
      [&] { blas::multiply_lower(Side::Right, Transpose::No, inv11, a21.bottomRows(n2 - rows)); });
  run_pair(
      true, [&] { blas::multiply_lower(Side::Left, Transpose::No, inv22, a21.leftCols(cols)); },
      [&] { blas::multiply_lower(Side::Left, Transpose::No, inv22, a21.rightCols(n1 - cols)); });
  a21 *= -1.0;
}

void lower_gram(Eigen::Ref<Matrix> a, int threads) {
  const Eigen::Index n = a.rows();
  if (threads < 2 || n < kParallelSize) {
    blas::lower_gram(a);
    return;
  }
  // M = [M11 0; M21 M22]:  M'M = [M11'M11 + M21'M21, .; M22'M21, M22'M22]
  const Eigen::Index n1 = n / 2, n2 = n - n1, cols = n1 / 2;
  const int inner = std::max(1, threads / 2);
  auto m21 = a.bottomLeftCorner(n2, n1);
  const auto m22 = a.bottomRightCorner(n2, n2);
  Matrix product = m21;  // M22' M21, computed while M22 and M21 still hold their inputs
  run_pair(
      true, [&] { blas::multiply_lower(Side::Left, Transpose::Yes, m22, product.leftCols(cols)); },
      [&] { blas::multiply_lower(Side::Left, Transpose::Yes, m22, product.rightCols(n1 - cols)); });
  run_pair(
      true,
      [&] {
        lower_gram(a.topLeftCorner(n1, n1), inner);
        blas::rank_update_lower(1.0, m21, Transpose::Yes, 1.0, a.topLeftCorner(n1, n1));
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
