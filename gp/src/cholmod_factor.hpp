#pragma once
/// @file cholmod_factor.hpp
/// Internal: sparse Cholesky factorisation with SuiteSparse CHOLMOD behind a small RAII wrapper, with
/// the same escalating-jitter contract as the dense factorisation (dense_cholesky.hpp), and the
/// result copied into a plain supernodal factor that the rest of the compact backend works on
/// (supernodal_factor.hpp), so that no CHOLMOD object outlives one factorisation.

#include <cstdint>
#include <memory>

#include "compact_pattern.hpp"
#include "gpilqg/gp/backend.hpp"
#include "supernodal_factor.hpp"

namespace gpilqg::gp::detail {

/// Outcome of factorising K = Kf + (noise_variance + jitter) I.
struct SparseFactorOutcome {
  FactorStatus status = FactorStatus::Failed;
  double jitter = 0.0;           ///< absolute jitter added (0 when Ok)
  bool over_budget = false;      ///< Failed because nnz(L) from the analysis exceeds the budget
  double factor_nonzeros = 0.0;  ///< nnz(L) of the symbolic analysis
};

/// CHOLMOD's symbolic analysis of a pattern (ordering, elimination tree, column counts c_j of L, the
/// diagonal included, supernodes): known before any numerical work.
struct SymbolicFactor {
  double nonzeros = 0.0;  ///< nnz(L) = sum_j c_j (CHOLMOD's Common->lnz)
  double flops = 0.0;     ///< sum_j c_j^2 (Common->fl), the flops of one LL' factorisation: N(N+1)(2N+1)/6 ~ N^3/3 dense
  /// Flops of SupernodalFactor::inverse_subset on these supernodes: sum_s 3 c^3 + 4 b c^2 + 2 b^2 c
  /// for supernode s of c columns with b rows below them (supernodal_factor.cpp).
  double inverse_subset_flops = 0.0;
};

/// Owns one cholmod_common (started and finished with it) and factorises symmetric matrices given by
/// their lower triangle in compressed-column form. Not copyable; one per thread.
class CholmodFactorizer {
 public:
  CholmodFactorizer();
  ~CholmodFactorizer();
  CholmodFactorizer(const CholmodFactorizer&) = delete;
  CholmodFactorizer& operator=(const CholmodFactorizer&) = delete;

  /// Fill-reducing ordering and symbolic analysis (CHOLMOD's default: AMD, METIS when AMD fills in
  /// badly), supernodal numerical factorisation of
  ///   A + (noise_variance + e) I,   A = the lower triangle `pattern` with `values` (same layout),
  /// for the smallest e of {0, schedule.first * scale, ... <= schedule.last * scale} that succeeds.
  /// "Succeeds" means CHOLMOD finds every pivot positive and every squared diagonal entry of L exceeds
  /// 16 eps times the largest diagonal entry of the factorised matrix (a smaller pivot is rounding
  /// noise: numerically singular, as in sparse_linalg.hpp). On success `factor` holds the supernodal
  /// LL' factor. Over budget (analysis nnz(L) > max_factor_nonzeros): Failed with over_budget, no
  /// numerical work done. Never throws on numerical trouble; throws std::runtime_error when CHOLMOD
  /// reports an error other than "not positive definite" (e.g. out of memory).
  SparseFactorOutcome factorize(const LowerPattern& pattern, const std::vector<double>& values, double noise_variance,
                                double scale, const JitterSchedule& schedule, std::int64_t max_factor_nonzeros,
                                SupernodalFactor& factor);

  /// The same ordering and symbolic analysis as factorize() on `pattern` alone (no values, no
  /// numerical work). Throws std::runtime_error when CHOLMOD reports an error.
  SymbolicFactor analyze(const LowerPattern& pattern);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gpilqg::gp::detail
