#pragma once
/// @file pair_block_kernels.hpp
/// The two products of moment_matching_pair_sums.cpp with one short dimension, the input dimension D
/// (5 for the cart-pole): per block of columns J of one pair of outputs,
///
///   form_exponents:   B(i, c) = min(r_i + c_j + sum_k L(i, k) R(j, k), cap),   j = j0 + c,
///   accumulate_block: O(i, k) += sum_c B(i, c) V(j0 + c, k),                   k < D.
///
/// As general matrix products (BLAS or Eigen) these run far below the processor's rate: with an inner
/// dimension of 5, packing and the write-back of each 4 x 4 tile dominate. Here each column is D
/// multiply-adds over a contiguous column (first) or D columns updated from one (second), loops the
/// compiler vectorises; they are compiled for each kind of vector_isa.hpp and the widest the processor
/// supports is used. All matrices are column-major with the given leading dimensions.

#include <Eigen/Core>

#include "vector_isa.hpp"

namespace gpilqg::gp::detail {

/// The arguments of form_exponents: B is rows x cols (leading dimension rows).
struct ExponentBlock {
  const double* lhs;      ///< L (rows x d), leading dimension lhs_stride
  Eigen::Index lhs_stride;
  const double* rhs;      ///< R(j0, 0): cols rows of R, leading dimension rhs_stride
  Eigen::Index rhs_stride;
  Eigen::Index d;
  const double* row_term;  ///< r (rows)
  const double* col_term;  ///< c(j0) (cols)
  double cap;
  Eigen::Index rows, cols;
  double* block;           ///< B (rows x cols)
};

void form_exponents(const ExponentBlock& e);
void form_exponents(const ExponentBlock& e, VectorIsa isa);  ///< with a given kind (tests, benchmarks)

/// The arguments of accumulate_block: O += B V(j0 : j0 + cols, :).
struct BlockUpdate {
  const double* block;  ///< B (rows x cols), leading dimension rows
  Eigen::Index rows, cols;
  const double* v;      ///< V(j0, 0): cols rows, leading dimension v_stride
  Eigen::Index v_stride;
  Eigen::Index d;
  double* out;          ///< O (rows x d), leading dimension out_stride
  Eigen::Index out_stride;
};

void accumulate_block(const BlockUpdate& u);
void accumulate_block(const BlockUpdate& u, VectorIsa isa);  ///< with a given kind (tests, benchmarks)

}  // namespace gpilqg::gp::detail
