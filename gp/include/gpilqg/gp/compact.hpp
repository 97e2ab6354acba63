#pragma once
/// @file compact.hpp
/// Exact GP regression with a compactly supported kernel, so that K is sparse and the whole data set
/// (N = 100,000 and more) can be used without a subsample (registry name "compact").
///
/// Kernel: Wendland's piecewise polynomial phi_{D,1} with ARD length-scales (GPML book eq. 4.21,
/// covPPard with v = 1; Wendland 1995, Theorem 5.2), with r the length-scale-scaled distance:
///
///   r^2 = sum_d (a_d - b_d)^2 / l_d^2,    j = floor(D / 2) + 2,
///   k(a, b) = sf^2 (1 - r)_+^(j+1) ((j + 1) r + 1).
///
/// Positive definiteness: (1 - r)_+^(j+1) ((j+1) r + 1) is positive definite on R^D exactly when
/// j >= floor(D / 2) + 2 (Wendland's condition for phi_{D,1}, l = floor(D/2) + k + 1 with k = 1); the
/// ARD scaling is a linear map of the inputs and keeps it positive definite. It is C^2 (twice
/// continuously differentiable, also at r = 0 and r = 1), so the mean and variance have continuous
/// input gradients. k vanishes for r >= 1: l_d is the support radius along input d (not the SE
/// length-scale; on the same data the fitted l_d are typically 2-4 times larger than the SE ones).
///
/// Derivatives (g(r) = -(1/r) dk/dr = sf^2 (j+1)(j+2) (1 - r)_+^j, finite at r = 0):
///   dk/d log l_d = g(r) (a_d - b_d)^2 / l_d^2,   dk/d log sf = 2 k,   dk/da_d = -g(r) (a_d - b_d) / l_d^2.
///
/// With K = Kf + (sn^2 + jitter) I = P' L L' P (CHOLMOD, fill-reducing permutation P, supernodal
/// numerical factorisation, then kept as a simplicial L), alpha = K^-1 y and Z = K^-1:
///   nlml = 0.5 y' alpha + sum_i log L_ii + N/2 log(2 pi)                     (GPML eq. 2.30)
///   d nlml / d theta = 0.5 sum_ij (Z_ij - alpha_i alpha_j) dK_ij / d theta     (GPML eq. 5.9)
/// dK/dtheta is zero outside the sparsity pattern of K, which lies inside that of P' (L + L') P, so
/// only the entries of Z on the pattern of L are needed. They are computed exactly (no sampling, no
/// approximation) by the Takahashi recurrence on the factor (the "sparse inverse subset"; Takahashi,
/// Fagan & Chen 1973; Campbell & Davis 1995): with the unit factor Lt = L diag(L)^-1 and d_i = L_ii^2,
///   Z_ji = -sum_{k in struct(L_:i)} Lt_ki Z_kj     (j in struct(L_:i), j > i)
///   Z_ii = 1 / d_i - sum_{k in struct(L_:i)} Lt_ki Z_ki,
/// for i = N-1 down to 0; every Z_kj it reads lies on the pattern of L (the fill pattern is chordal).
/// Cost: about that of the factorisation itself, memory one more array of nnz(L) doubles.
///
/// Prediction at z with the support set S = {i : r(x_i, z) < 1} (a grid search over the scaled inputs)
/// and k = k(X_S, z):
///   mean     = k' alpha_S                 (O(|S| D))
///   variance = sf^2 - |v|^2,  v = L^-1 P k  (a sparse triangular solve over the elimination-tree
///                                            reach of S, not over all N)
///   d mean / dz_d     = -(1/l_d^2) sum_{i in S} alpha_i g(r_i) (z_d - x_id)
///   d variance / dz_d =  (2/l_d^2) sum_{i in S} w_i g(r_i) (z_d - x_id),  w = K^-1 k = P' L^-T v,
/// where w is needed only on S, and (L^-T v) restricted to the reach is computed from the reach alone
/// (the reach is closed under elimination-tree ancestors). Far from all data S is empty: mean 0,
/// variance sf^2, zero gradients.
///
/// Cost control: the sparsity depends on the length-scales. The fitter's box caps the support radii
/// (CompactOptions::max_neighbours). An evaluation whose kernel matrix would
/// have more than `max_factor_nonzeros` entries, or whose symbolic factor would (CHOLMOD's analysis,
/// before any numerical work), is reported as FactorStatus::Failed (value +infinity), so the fitter
/// backtracks to shorter supports instead of running out of memory; condition() throws for it.

#include <cstdint>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp {

struct CompactOptions {
  /// The data-driven start scales the input spreads by one common factor so that a training point
  /// has about this many neighbours within the support (the median over up to 512 sampled points).
  int initial_neighbours = 32;
  /// Upper bound on the support for the fitter: log l_d <= log l_d(start) + log(max_neighbours /
  /// initial_neighbours), i.e. one input alone can widen the support by that ratio (so that ARD can
  /// switch irrelevant inputs off; the neighbour count is proportional to prod_d l_d). A box the
  /// optimiser handles well; the joint growth of all l_d is stopped by max_factor_nonzeros below (an
  /// evaluation beyond it is Failed, and L-BFGS backtracks). Must be >= initial_neighbours.
  int max_neighbours = 256;
  /// Largest number of nonzeros of K's lower triangle and of the Cholesky factor L (each costs 12
  /// bytes; the factor is held twice during a gradient: L and the inverse subset Z). 5e7 is about
  /// 0.6 GB per copy.
  std::int64_t max_factor_nonzeros = 50'000'000;
  /// Threads for the neighbour search and for batch prediction (CHOLMOD's BLAS decides its own).
  int threads = 1;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// What one evaluation at given hyperparameters will cost, from CHOLMOD's symbolic analysis of the
/// pattern K will have there (the same ordering and supernodes as the fit's; no kernel values, no
/// numerical work). With c_j the entries of column j of L (diagonal included):
///   factor_nonzeros = sum_j c_j,   factorisation_flops = sum_j c_j^2
/// (CHOLMOD's Common->lnz and Common->fl): N(N+1)(2N+1)/6 ~ N^3/3 when L is dense, N when K is
/// diagonal, 4N - 3 for a path (tridiagonal K, no fill). The gradient's sparse inverse subset works
/// per supernode (c columns, b rows below them): the diagonal block inverted by a triangular solve
/// and multiplied out as full c x c products, then the products with the rows below,
///   inverse_subset_flops = sum_s 3 c^3 + 4 b c^2 + 2 b^2 c
/// (3 N^3 when L is dense, one supernode): in 17 dimensions about 9 times the factorisation.
struct CompactFactorAnalysis {
  std::int64_t kernel_nonzeros = 0;  ///< entries of K's lower triangle, diagonal included
  double factor_nonzeros = 0.0;
  double factorisation_flops = 0.0;
  double inverse_subset_flops = 0.0;
  /// K's pattern or L exceeds CompactOptions::max_factor_nonzeros: an evaluation there fails at once
  /// (no numerical work). When K's pattern is over, nothing was analysed and the counts are 0.
  bool over_budget = false;
};

class CompactBackend final : public GpBackend {
 public:
  explicit CompactBackend(CompactOptions options = {});
  std::string_view name() const override { return "compact"; }
  const CompactOptions& options() const { return options_; }

  std::unique_ptr<MarginalLikelihoodObjective> objective(const TrainingSet& data,
                                                         const FitOptions& options) const override;
  /// Throws std::runtime_error when K is not positive definite even with the largest jitter, or when
  /// the factor would exceed max_factor_nonzeros (naming both numbers).
  std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters,
                                      const JitterSchedule& jitter = {}) const override;

  /// The symbolic analysis at `parameters` ([log l; log sf; log sn], D + 2 entries, e.g. the head of
  /// objective(data)->initial_parameters()). Costs the neighbour search and the ordering, O(nnz(K))
  /// memory. Throws std::invalid_argument for degenerate data or a wrongly sized / non-finite vector.
  CompactFactorAnalysis analyze(const TrainingSet& data, const VectorCRef& parameters) const;

 private:
  CompactOptions options_;
};

}  // namespace gpilqg::gp
