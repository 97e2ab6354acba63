#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "exact_gp_internal.hpp"
#include "parallel.hpp"

namespace gpilqg::gp::detail {

namespace {

/// Columns first, first + stride, ... of the lower triangle of K(X, X).
void kernel_lower_columns(const Matrix& x, const Vector& inverse_squared_lengthscales, double signal_variance,
                          Matrix& k, Eigen::Index first, Eigen::Index stride) {
  const Eigen::Index n = x.rows();
  for (Eigen::Index j = first; j < n; j += stride) {
    auto column = k.col(j).tail(n - j).array();
    column.setZero();
    for (Eigen::Index d = 0; d < x.cols(); ++d)
      column += inverse_squared_lengthscales(d) * (x.col(d).tail(n - j).array() - x(j, d)).square();
    column = signal_variance * (-0.5 * column).exp();
  }
}

}  // namespace

void kernel_lower(const Matrix& x, const Vector& inverse_squared_lengthscales, double signal_variance, Matrix& k,
                  int threads) {
  const Eigen::Index n = x.rows();
  const int max_workers = n >= 512 ? threads : 1;
  run_workers(threads, max_workers, [&](int worker, int workers) {
    kernel_lower_columns(x, inverse_squared_lengthscales, signal_variance, k, worker, workers);
  });
}

void check_exact_parameters(const VectorCRef& parameters, int input_dim, const char* who) {
  if (parameters.size() != Hyperparameters::count(input_dim))
    throw std::invalid_argument(std::string(who) + ": parameter vector has " + std::to_string(parameters.size()) +
                                " entries; expected D + 2 = " + std::to_string(Hyperparameters::count(input_dim)) +
                                " ([log l; log sf; log sn]) for D = " + std::to_string(input_dim));
}

double nlml_from_factor(const Matrix& factor, const Vector& targets, const Vector& alpha) {
  return 0.5 * targets.dot(alpha) + factor.diagonal().array().log().sum() +
         0.5 * static_cast<double>(targets.size()) * std::log(2.0 * std::numbers::pi);
}

void solve_alpha(const Matrix& factor, const Vector& targets, Vector& alpha) {
  alpha = targets;
  factor.triangularView<Eigen::Lower>().solveInPlace(alpha);
  factor.triangularView<Eigen::Lower>().adjoint().solveInPlace(alpha);
}

}  // namespace gpilqg::gp::detail
