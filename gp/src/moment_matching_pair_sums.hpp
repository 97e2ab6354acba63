#pragma once
/// @file moment_matching_pair_sums.hpp
/// The N_a x N_b part of one pair of outputs (a, b) of SeArdMomentMatcher's covariance
/// (moment_matching_covariance.cpp derives the formulas): with D = (A_a Xi) A_b' + r 1' + 1 c',
///
///   E_ij     = expm1(min(D_ij, 700)),
///   Omega_ij = gamma_ai gamma_bj E_ij - [subtract_kinv] (E_ij + 1) Kinv_a,ij q_ai q_aj   (the second term: a = b),
///
/// and of them only the sums the covariance and its derivatives use:
///
///   centred      = gamma_a' E gamma_b                      (a = b),
///   kinv_centred = sum_ij Kinv_a,ij q_ai q_aj E_ij          (a = b),
///   total        = 1' Omega 1                              (a != b, or derivatives),
///   row_sums     = Omega 1,  col_sums = Omega' 1,  omega_v = Omega V_b   (derivatives).
///
/// E is never held whole. It is formed kPairBlock columns at a time (N_a x 64 doubles, which stay in
/// the processor's cache) and reduced at once: formed whole and then read by each sum in turn, the
/// N x N matrix went through memory about ten times per pair (2.9 MB each time at N = 600), and the
/// propagation was bound by memory traffic. For a = b, E and Omega are symmetric: each block of
/// columns covers its rows from the diagonal block down, the diagonal block counted once and the rows
/// below it twice (for their mirror image above the diagonal).

#include "gpilqg/core/types.hpp"
#include "gpilqg/gp/moment_matcher.hpp"

namespace gpilqg::gp::detail {

/// The inputs of one pair; every block has N_a (rows) or N_b (columns) rows.
struct PairTerms {
  Eigen::Ref<const Matrix> cross_lhs;  ///< A_a Xi (N_a x D)
  Eigen::Ref<const Matrix> cross_rhs;  ///< A_b (N_b x D)
  Eigen::Ref<const Vector> row_term;   ///< r (N_a): the row part of D, with the pair's constant
  Eigen::Ref<const Vector> col_term;   ///< c (N_b): the column part of D
  Eigen::Ref<const Vector> gamma_a;    ///< beta_a .* q_a (N_a)
  Eigen::Ref<const Vector> gamma_b;    ///< beta_b .* q_b (N_b)
  Eigen::Ref<const Matrix> centred_b;  ///< V_b (N_b x D), for Omega V_b
  const Matrix* kinv = nullptr;        ///< a = b: Kinv_a (N_a x N_a), which makes the pair symmetric; else null
  const Vector* kernel_mean = nullptr;  ///< a = b: q_a (N_a)
};

struct PairSums {
  double centred = 0.0;       ///< a = b only
  double kinv_centred = 0.0;  ///< a = b only
  double total = 0.0;         ///< a != b, or with derivatives
};

/// The sums of the file comment. With `derivatives`, row_sums (N_a), col_sums (N_b) and omega_v
/// (N_a x D) are written to the first entries of w.row_sums, w.col_sums and w.omega_v; w.nn holds
/// the blocks. Allocation-free once w is sized for N_max.
PairSums pair_sums(const PairTerms& in, bool subtract_kinv, bool derivatives, MomentMatchWorkerScratch& w);

}  // namespace gpilqg::gp::detail
