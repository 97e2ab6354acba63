#pragma once
/// @file blas_lapack.hpp
/// Internal: the dense BLAS-3 and LAPACK routines the GP backends spend their time in, called through
/// the system's BLAS/LAPACK (Debian: libblas.so.3 / liblapack.so.3, which update-alternatives points
/// to OpenBLAS when it is installed; scripts/bootstrap.sh installs the serial OpenBLAS). OpenBLAS
/// picks AVX2 or AVX-512 kernels at run time, so a baseline x86-64 build gets them without -march.
/// CHOLMOD calls the same library.
///
/// Threads: every call here runs on the calling thread. The project's own threads (the GP outputs
/// fitted concurrently, the split of large factorisations in dense_cholesky.cpp, MPI ranks) are the
/// only parallelism, so nothing oversubscribes the cores and results do not depend on the thread
/// count. OpenBLAS is told to use one thread when this library loads (openblas_set_num_threads(1));
/// docs/building.md#blas.
///
/// All wrappers take column-major Eigen blocks (Eigen::Ref, any outer stride) and touch only the
/// triangle they name.

#include <string>

#include "gpilqg/core/types.hpp"

namespace gpilqg::gp::detail::blas {

enum class Side { Left, Right };
enum class Transpose { No, Yes };

/// In place: lower triangle of A -> L with A = L L' (dpotrf). Returns false when A is not
/// numerically positive definite (then the lower triangle holds garbage).
bool cholesky_lower(Eigen::Ref<Matrix> a);

/// In place: lower triangle of a non-singular L -> L^-1 (dtrtri).
void invert_lower(Eigen::Ref<Matrix> l);

/// In place: lower triangle of M -> lower triangle of M' M (dlauum).
void lower_gram(Eigen::Ref<Matrix> m);

/// In place: B := op(L)^-1 B (Side::Left) or B op(L)^-1 (Side::Right), L lower triangular (dtrsm).
void solve_lower(Side side, Transpose transpose, const Eigen::Ref<const Matrix>& l, Eigen::Ref<Matrix> b);

/// In place: B := op(L) B (Side::Left) or B op(L) (Side::Right), L lower triangular (dtrmm).
void multiply_lower(Side side, Transpose transpose, const Eigen::Ref<const Matrix>& l, Eigen::Ref<Matrix> b);

/// Lower triangle of C := beta C + alpha A A' (Transpose::No) or beta C + alpha A' A (dsyrk).
void rank_update_lower(double alpha, const Eigen::Ref<const Matrix>& a, Transpose transpose, double beta,
                       Eigen::Ref<Matrix> c);

/// C := beta C + alpha op(A) op(B) (dgemm).
void multiply(double alpha, const Eigen::Ref<const Matrix>& a, Transpose transpose_a, const Eigen::Ref<const Matrix>& b,
              Transpose transpose_b, double beta, Eigen::Ref<Matrix> c);

/// The BLAS library the process runs on, as the dynamic loader resolved it (for reports), e.g.
/// "/usr/lib/x86_64-linux-gnu/openblas-serial/libblas.so.3 (OpenBLAS 0.3.21 ... SkylakeX)".
std::string library_description();

}  // namespace gpilqg::gp::detail::blas
