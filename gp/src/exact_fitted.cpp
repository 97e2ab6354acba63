/// The conditioned exact GP: cached alpha and L^-1 (or L), prediction with input gradients.

#include <algorithm>
#include <stdexcept>
#include <string>

#include "dense_cholesky.hpp"
#include "exact_gp_internal.hpp"
#include "parallel.hpp"

namespace gpilqg::gp::detail {

namespace {

/// Up to this many training points the fitted model caches L^-1 (N^3/3 flops once) so that a query's
/// variance is two triangular matrix-vector products instead of two triangular solves; above it, it
/// keeps L and solves (batch prediction uses blocked solves with many right-hand sides).
/// Why L^-1 and not K^-1: var = sf^2 - |L^-1 k|^2 loses about eps sqrt(cond K) sf^2 to rounding,
/// sf^2 - k' K^-1 k about eps cond(K) sf^2, which on nearly noise-free data (cond K ~ N sf^2 / sn^2)
/// swamps the small variances near the data that the residual model's G is made of.
constexpr int kMaxPointsWithCachedInverseFactor = 3000;

class ExactFittedGp final : public FittedGp {
 public:
  ExactFittedGp(TrainingSet data, const VectorCRef& parameters, const JitterSchedule& jitter, int threads)
      : data_(std::move(data)), threads_(threads), parameters_(parameters) {
    const int d = data_.input_dim();
    check_exact_parameters(parameters_, d, "ExactGpBackend::condition");
    const Hyperparameters h = Hyperparameters::unpack(parameters_, d);
    inverse_squared_lengthscales_ = (-2.0 * h.log_lengthscales.array()).exp();
    signal_variance_ = h.signal_variance();
    const Eigen::Index n = data_.size();
    auto fill = [this, threads](Matrix& k) {
      kernel_lower(data_.inputs, inverse_squared_lengthscales_, signal_variance_, k, threads);
    };
    const FactorOutcome outcome =
        cholesky_with_jitter(n, fill, signal_variance_, h.noise_variance(), jitter, factor_, threads);
    if (outcome.status == FactorStatus::Failed)
      throw std::runtime_error("ExactGpBackend::condition: K is not positive definite even with jitter " +
                               std::to_string(outcome.jitter) + " on " + std::to_string(n) + " points");
    report_.status = outcome.status;
    report_.jitter = outcome.jitter;
    solve_alpha(factor_, data_.targets, alpha_);
    report_.negative_log_marginal_likelihood = nlml_from_factor(factor_, data_.targets, alpha_);
    if (n <= kMaxPointsWithCachedInverseFactor) {
      invert_lower_triangular(factor_, threads);
      factor_.triangularView<Eigen::StrictlyUpper>().setZero();
      inverse_factor_ = std::move(factor_);
      factor_ = Matrix();
    }
  }

  std::string_view backend_name() const override { return "exact"; }
  int input_dim() const override { return data_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }

  /// mean = k' alpha, variance = sf^2 - |v|^2 with v = L^-1 k (GPML eqs. 2.25, 2.26, algorithm 2.1);
  /// with r_i = x_i - z,
  ///   d mean / dz_d     =  (1/l_d^2) sum_i alpha_i k_i r_id
  ///   d variance / dz_d = -(2/l_d^2) sum_i w_i k_i r_id,  w = K^-1 k = L^-T v.
  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int d = input_dim();
    if (z.size() != d)
      throw std::invalid_argument("ExactGp::predict: input has " + std::to_string(z.size()) + " entries; expected " +
                                  std::to_string(d));
    const Eigen::Index n = data_.size();
    PredictionWorkspace& ws = out.workspace;
    ws.cross.resize(n);
    auto k = ws.cross.array();
    k.setZero();
    for (int dim = 0; dim < d; ++dim)
      k += inverse_squared_lengthscales_(dim) * (data_.inputs.col(dim).array() - z(dim)).square();
    k = signal_variance_ * (-0.5 * k).exp();
    out.mean = ws.cross.dot(alpha_);
    if (request.gradients) {
      ws.extra.resize(n);
      ws.extra.array() = alpha_.array() * k;
      out.mean_gradient.resize(d);
      for (int dim = 0; dim < d; ++dim)
        out.mean_gradient(dim) =
            inverse_squared_lengthscales_(dim) * (data_.inputs.col(dim).dot(ws.extra) - z(dim) * out.mean);
    }
    if (!request.variance) return;
    ws.weighted.resize(n);
    double explained = 0.0;  // k' K^-1 k
    if (inverse_factor_.size() != 0) {
      ws.weighted.noalias() = inverse_factor_.triangularView<Eigen::Lower>() * ws.cross;
      explained = ws.weighted.squaredNorm();
      if (request.gradients) {
        ws.extra.noalias() = inverse_factor_.triangularView<Eigen::Lower>().transpose() * ws.weighted;
        ws.weighted.swap(ws.extra);
      }
    } else {
      ws.weighted = ws.cross;
      factor_.triangularView<Eigen::Lower>().solveInPlace(ws.weighted);
      explained = ws.weighted.squaredNorm();
      if (request.gradients) factor_.triangularView<Eigen::Lower>().adjoint().solveInPlace(ws.weighted);
    }
    out.variance = std::max(signal_variance_ - explained, 0.0);
    if (request.gradients) {
      ws.extra.array() = ws.weighted.array() * k;
      out.variance_gradient.resize(d);
      for (int dim = 0; dim < d; ++dim)
        out.variance_gradient(dim) =
            -2.0 * inverse_squared_lengthscales_(dim) * (data_.inputs.col(dim).dot(ws.extra) - z(dim) * explained);
    }
  }

  /// Blocked: K(X, Z) for up to 512 points at a time, mean = Ks' alpha, variance = sf^2 - colwise
  /// |L^-1 Ks|^2 (a triangular product or solve with many right-hand sides). With several threads,
  /// each takes a contiguous share of the points.
  void predict(const MatrixCRef& points, Vector& mean, Vector& variance) const override {
    const int d = input_dim();
    if (points.cols() != d)
      throw std::invalid_argument("ExactGp::predict: points have " + std::to_string(points.cols()) +
                                  " columns; expected " + std::to_string(d));
    const Eigen::Index total = points.rows();
    mean.resize(total);
    variance.resize(total);
    constexpr Eigen::Index kBlock = 512;
    const int max_workers = static_cast<int>(std::min<Eigen::Index>(total / 64 + 1, threads_));
    run_workers(threads_, max_workers, [&](int worker, int workers) {
      const Eigen::Index begin = total * worker / workers, end = total * (worker + 1) / workers;
      Matrix cross, solved;
      for (Eigen::Index start = begin; start < end; start += kBlock) {
        const Eigen::Index count = std::min(kBlock, end - start);
        predict_block(points.middleRows(start, count), cross, solved, mean.segment(start, count),
                      variance.segment(start, count));
      }
    });
  }

 private:
  void predict_block(const MatrixCRef& points, Matrix& cross, Matrix& solved, Eigen::Ref<Vector> mean,
                     Eigen::Ref<Vector> variance) const {
    const Eigen::Index n = data_.size(), count = points.rows();
    cross.setZero(n, count);
    for (Eigen::Index c = 0; c < count; ++c) {
      auto k = cross.col(c).array();
      for (int dim = 0; dim < input_dim(); ++dim)
        k += inverse_squared_lengthscales_(dim) * (data_.inputs.col(dim).array() - points(c, dim)).square();
      k = signal_variance_ * (-0.5 * k).exp();
    }
    mean.noalias() = cross.transpose() * alpha_;
    if (inverse_factor_.size() != 0) {
      solved.noalias() = inverse_factor_.triangularView<Eigen::Lower>() * cross;
      variance = solved.colwise().squaredNorm().transpose();
    } else {
      factor_.triangularView<Eigen::Lower>().solveInPlace(cross);
      variance = cross.colwise().squaredNorm().transpose();
    }
    variance = (signal_variance_ - variance.array()).max(0.0).matrix();
  }

  TrainingSet data_;
  int threads_;
  Vector parameters_;
  ConditioningReport report_;
  Vector inverse_squared_lengthscales_;
  double signal_variance_ = 0.0;
  Vector alpha_;
  Matrix factor_;          // L = chol(K), kept only when L^-1 is not cached
  Matrix inverse_factor_;  // L^-1 (lower, zero above) when N <= kMaxPointsWithCachedInverseFactor
};

}  // namespace

std::unique_ptr<FittedGp> make_exact_fitted_gp(TrainingSet data, const VectorCRef& parameters,
                                               const JitterSchedule& jitter, int threads) {
  return std::make_unique<ExactFittedGp>(std::move(data), parameters, jitter, threads);
}

}  // namespace gpilqg::gp::detail
