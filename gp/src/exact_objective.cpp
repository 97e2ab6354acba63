/// The exact GP's negative log marginal likelihood and its gradient (GPML eqs. 2.30 and 5.9).

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "dense_cholesky.hpp"
#include "exact_gp_internal.hpp"
#include "parallel.hpp"

namespace gpilqg::gp::detail {

namespace {

/// From this many points on, the O(N^2 D) gradient sums run on the objective's threads (below it,
/// starting the helpers costs more than the sums; the kernel matrix uses the same bound).
constexpr Eigen::Index kParallelGradientSize = 512;

class ExactObjective final : public MarginalLikelihoodObjective {
 public:
  ExactObjective(TrainingSet data, const FitOptions& options, int threads)
      : data_(std::move(data)),
        threads_(threads),
        min_noise_std_(options.min_noise_std),
        min_noise_ratio_(options.min_noise_ratio),
        jitter_(options.jitter) {}

  int parameter_count() const override { return Hyperparameters::count(data_.input_dim()); }
  int input_dim() const override { return data_.input_dim(); }
  ParameterBounds bounds() const override { return hyperparameter_bounds(data_, min_noise_std_, min_noise_ratio_); }
  Vector initial_parameters() const override { return initial_hyperparameters(data_).pack(); }

  /// nlml (GPML eq. 2.30) and its gradient (GPML eq. 5.9) with W = K^-1 - alpha alpha', K = Kf +
  /// diag(sn^2 + v_i) (v_i known, fixed: they add no term to the gradient):
  ///   d/d log l_d = 0.5 sum_ij W_ij Kf_ij (x_id - x_jd)^2 / l_d^2
  ///   d/d log sf  = sum_ij W_ij Kf_ij,     d/d log sn = sn^2 tr(W)
  /// Only the lower triangle is touched (W and Kf are symmetric, the diagonal of (x_i - x_j)^2 is 0).
  NlmlEvaluation evaluate(const VectorCRef& theta, Vector* gradient) override {
    const int d = data_.input_dim();
    check_exact_parameters(theta, d, "ExactGp objective");
    const Eigen::Index n = data_.size();
    const Vector inverse_squared_lengthscales = (-2.0 * theta.head(d).array()).exp();
    const double signal_variance = std::exp(2.0 * theta(d));
    const double noise_variance = std::exp(2.0 * theta(d + 1));
    if (kernel_.rows() != n) kernel_.resize(n, n);
    kernel_lower(data_.inputs, inverse_squared_lengthscales, signal_variance, kernel_, threads_);
    // K = Kf + diag(sn^2 + v_i): v the known noise variances (TrainingSet::noise_variance), if any.
    const Vector& known = data_.noise_variance;
    const auto fill = [this, n, &known](Matrix& target) {
      for (Eigen::Index j = 0; j < n; ++j) target.col(j).tail(n - j) = kernel_.col(j).tail(n - j);
      if (known.size() > 0) target.diagonal() += known;
    };
    const FactorOutcome outcome = cholesky_with_jitter(
        n, fill, kernel_.diagonal().mean() + (known.size() > 0 ? known.mean() : 0.0), noise_variance, jitter_, factor_,
        threads_);
    NlmlEvaluation result{0.0, outcome.status, outcome.jitter};
    if (outcome.status == FactorStatus::Failed) {
      result.value = std::numeric_limits<double>::infinity();
      if (gradient != nullptr) gradient->setZero(parameter_count());
      return result;
    }
    solve_alpha(factor_, data_.targets, alpha_);
    result.value = nlml_from_factor(factor_, data_.targets, alpha_);
    if (gradient == nullptr) return result;

    inverse_from_cholesky(factor_, threads_);  // factor_ now holds K^-1 (lower)
    gradient->setZero(parameter_count());
    // Worker w sums columns w, w + workers, ... (column j has n - j - 1 entries below the diagonal,
    // so the strides balance) into its own partial sums, which are added in worker order: the same
    // operations in the same order on every run with the same number of threads.
    const int workers = n >= kParallelGradientSize ? std::max(1, threads_) : 1;
    if (static_cast<int>(partial_.size()) < workers) {
      partial_.resize(static_cast<std::size_t>(workers));
      weighted_.resize(static_cast<std::size_t>(workers));
    }
    for (int w = 0; w < workers; ++w) partial_[static_cast<std::size_t>(w)].setZero(d + 2);
    run_workers(threads_, workers, [&](int worker, int count) { gradient_columns(alpha_, worker, count); });
    for (int w = 0; w < workers; ++w) *gradient += partial_[static_cast<std::size_t>(w)];
    const double sum_weighted_kernel = (*gradient)(d);
    const double trace_w = (*gradient)(d + 1);
    // The strict lower triangle counts twice in the full sums; the 0.5 of eq. 5.9 cancels that.
    gradient->head(d).array() *= inverse_squared_lengthscales.array();
    (*gradient)(d) = sum_weighted_kernel;
    (*gradient)(d + 1) = noise_variance * trace_w;
    if (!gradient->allFinite() || !std::isfinite(result.value)) {
      // Overflow in an extreme corner of the box: report as a failed evaluation, never a NaN.
      gradient->setZero();
      result.value = std::numeric_limits<double>::infinity();
      result.status = FactorStatus::Failed;
    }
    return result;
  }

 private:
  /// Columns first, first + stride, ... of the sums of evaluate() into partial_[first]: entries 0..D-1
  /// the length-scale sums sum_ij W_ij Kf_ij (x_id - x_jd)^2 (before the factor 1 / l_d^2), entry D
  /// sum_ij W_ij Kf_ij, entry D + 1 tr(W), from factor_ = K^-1 and kernel_ = Kf (lower triangles).
  void gradient_columns(const Vector& alpha, int first, int stride) {
    const int d = data_.input_dim();
    const Eigen::Index n = data_.size();
    const Matrix& inverse = factor_;
    Vector& sums = partial_[static_cast<std::size_t>(first)];
    Vector& weighted = weighted_[static_cast<std::size_t>(first)];
    if (weighted.size() != n) weighted.resize(n);
    for (Eigen::Index j = first; j < n; j += stride) {
      const double w_jj = inverse(j, j) - alpha(j) * alpha(j);
      sums(d + 1) += w_jj;
      sums(d) += w_jj * kernel_(j, j);
      const Eigen::Index m = n - j - 1;
      if (m == 0) continue;
      auto q = weighted.head(m).array();
      q = (inverse.col(j).tail(m).array() - alpha(j) * alpha.tail(m).array()) * kernel_.col(j).tail(m).array();
      sums(d) += 2.0 * q.sum();
      for (int dim = 0; dim < d; ++dim)
        sums(dim) += (q * (data_.inputs.col(dim).tail(m).array() - data_.inputs(j, dim)).square()).sum();
    }
  }

  TrainingSet data_;
  int threads_;
  double min_noise_std_;
  double min_noise_ratio_;
  JitterSchedule jitter_;
  Matrix kernel_;   // lower triangle of Kf = K(X, X) without noise
  Matrix factor_;   // chol(K), then K^-1 (lower)
  Vector alpha_;
  std::vector<Vector> weighted_;  // per worker
  std::vector<Vector> partial_;   // per worker: the sums of gradient_columns
};

// ---------------------------------------------------------------------------------------------------

}  // namespace

std::unique_ptr<MarginalLikelihoodObjective> make_exact_objective(TrainingSet data, const FitOptions& options,
                                                                  int threads) {
  return std::make_unique<ExactObjective>(std::move(data), options, threads);
}

}  // namespace gpilqg::gp::detail
