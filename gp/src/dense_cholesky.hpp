#pragma once
/// @file dense_cholesky.hpp
/// Internal dense linear algebra of the GP backends: Cholesky with escalating jitter, and the inverse
/// of a symmetric positive definite matrix from its Cholesky factor in N^3/3 + N^3/3 flops (LAPACK's
/// dtrtri + dlauum), instead of the 2 N^3 of solving against the identity. The work runs in the
/// system's LAPACK/BLAS (blas_lapack.hpp: OpenBLAS's AVX2/AVX-512 kernels where installed).
///
/// All routines work on the lower triangle only and never read or write the strictly upper part.
/// `threads` > 1 splits matrices of order >= 384 into 2 x 2 blocks whose BLAS-3 updates run on two
/// threads. The split changes the rounding order against `threads` = 1, but not from run to run:
/// every entry is computed by the same sequence of operations whichever thread computes it.

#include <functional>

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp::detail {

struct FactorOutcome {
  FactorStatus status = FactorStatus::Ok;
  double jitter = 0.0;
};

/// factor := chol(kernel + (noise_variance + jitter) I), lower triangle, for the smallest jitter of
/// the schedule that succeeds (jitter 0 first). `kernel`'s lower triangle is read; `factor` is resized
/// to match (no allocation when it already has the size). On Failed, `factor` holds garbage.
FactorOutcome cholesky_with_jitter(const Matrix& kernel, double noise_variance, const JitterSchedule& schedule,
                                   Matrix& factor, int threads = 1);

/// The same without a separate kernel matrix: `fill_kernel_lower(factor)` writes the lower triangle
/// of the noise-free kernel matrix into `factor` (already sized n x n) and is called again before
/// every retry; `mean_kernel_diagonal` scales the jitter. Halves the memory for large N.
FactorOutcome cholesky_with_jitter(Eigen::Index n, const std::function<void(Matrix&)>& fill_kernel_lower,
                                   double mean_kernel_diagonal, double noise_variance,
                                   const JitterSchedule& schedule, Matrix& factor, int threads = 1);

/// In place: lower triangle A -> chol(A) (dpotrf; right-looking 2 x 2 blocks over threads). False when A is not
/// numerically positive definite (then the lower triangle holds garbage).
bool cholesky_in_place(Eigen::Ref<Matrix> lower, int threads = 1);

/// In place: lower triangle L -> L^-1 (dtrtri; 2 x 2 blocks over threads).
void invert_lower_triangular(Eigen::Ref<Matrix> lower, int threads = 1);

/// In place: lower triangle M -> lower triangle of M' M (dlauum). With M = L^-1 this is K^-1.
void lower_gram(Eigen::Ref<Matrix> lower, int threads = 1);

/// In place: lower triangle of chol(K) -> lower triangle of K^-1.
void inverse_from_cholesky(Eigen::Ref<Matrix> factor, int threads = 1);

/// Copies the strictly lower triangle onto the strictly upper one.
void symmetrize_from_lower(Matrix& matrix);

}  // namespace gpilqg::gp::detail
