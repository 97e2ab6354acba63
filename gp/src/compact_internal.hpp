#pragma once
/// @file compact_internal.hpp
/// Internal pieces shared by the compact backend's objective (compact_objective.cpp), fitted model
/// (compact_fitted.cpp) and backend (compact_backend.cpp): the sparse kernel matrix and its factor.

#include <memory>
#include <vector>

#include "cholmod_factor.hpp"
#include "compact_kernel.hpp"
#include "compact_pattern.hpp"
#include "gpilqg/gp/compact.hpp"
#include "supernodal_factor.hpp"

namespace gpilqg::gp::detail {

/// K = Kf + (sn^2 + jitter) I for one parameter vector: the pattern of Kf's lower triangle (original
/// order), its values, and the factor.
struct CompactSystem {
  LowerPattern pattern;
  std::vector<double> values;  ///< Kf on `pattern`
  SupernodalFactor factor;
  SparseFactorOutcome outcome;
};

/// Builds the pattern with `grid` (over the same inputs and length-scales as `kernel`), the values and
/// the factor. Over budget (pattern or factor larger than options.max_factor_nonzeros): Failed with
/// outcome.over_budget. Numerical failure even with the largest jitter: Failed.
void build_compact_system(const Matrix& inputs, const WendlandKernel& kernel, const NeighbourGrid& grid,
                          double noise_variance, const JitterSchedule& jitter, const CompactOptions& options,
                          CholmodFactorizer& factorizer, CompactSystem& system);

/// 0.5 y' alpha + sum log L_ii + N/2 log(2 pi), alpha = K^-1 y written into `alpha`.
double compact_nlml(const SupernodalFactor& factor, const Vector& targets, Vector& alpha);

/// Throws std::invalid_argument unless the vector has D + 2 finite entries.
void check_compact_parameters(const VectorCRef& parameters, int input_dim, const char* who);

std::unique_ptr<MarginalLikelihoodObjective> make_compact_objective(TrainingSet data, const FitOptions& options,
                                                                    const CompactOptions& compact);
std::unique_ptr<FittedGp> make_compact_fitted_gp(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter, const CompactOptions& compact);

}  // namespace gpilqg::gp::detail
