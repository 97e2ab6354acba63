#pragma once
/// @file exact_gp_internal.hpp
/// Internal pieces shared by the exact GP's objective (exact_objective.cpp), its fitted model
/// (exact_fitted.cpp) and the backend (exact_gp.cpp).

#include <memory>

#include "gpilqg/gp/exact_gp.hpp"

namespace gpilqg::gp::detail {

/// Writes the lower triangle (diagonal sf^2) of K(X, X) into `k` (already N x N), column by column so
/// that the innermost loop runs over contiguous points of one input dimension (X is N x D,
/// column-major). With several threads, worker w takes columns w, w + workers, ... (balanced).
void kernel_lower(const Matrix& x, const Vector& inverse_squared_lengthscales, double signal_variance, Matrix& k,
                  int threads = 1);

/// Throws std::invalid_argument unless the vector has D + 2 entries.
void check_exact_parameters(const VectorCRef& parameters, int input_dim, const char* who);

/// 0.5 y' alpha + sum log L_ii + N/2 log(2 pi)   (GPML eq. 2.30 through the factor)
double nlml_from_factor(const Matrix& factor, const Vector& targets, const Vector& alpha);

/// alpha = K^-1 y through the factor: L z = y, L' alpha = z.
void solve_alpha(const Matrix& factor, const Vector& targets, Vector& alpha);

std::unique_ptr<MarginalLikelihoodObjective> make_exact_objective(TrainingSet data, const FitOptions& options,
                                                                  int threads);
std::unique_ptr<FittedGp> make_exact_fitted_gp(TrainingSet data, const VectorCRef& parameters,
                                               const JitterSchedule& jitter, int threads);

}  // namespace gpilqg::gp::detail
