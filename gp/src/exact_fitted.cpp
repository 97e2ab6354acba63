/// The conditioned exact GP: cached alpha and L^-1 (or L), prediction with input gradients.

#include <algorithm>
#include <stdexcept>
#include <string>

#include "blas_lapack.hpp"
#include "dense_cholesky.hpp"
#include "exact_gp_internal.hpp"
#include "exact_prediction.hpp"
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
    predictor_ = ExactPredictor(&data_.inputs, (-2.0 * h.log_lengthscales.array()).exp(), h.signal_variance());
    const double sf2 = predictor_.signal_variance();
    const Eigen::Index n = data_.size();
    Matrix factor;
    const Vector& known = data_.noise_variance;  // K = Kf + diag(sn^2 + v_i) (TrainingSet::noise_variance)
    auto fill = [this, threads, sf2, &known](Matrix& k) {
      kernel_lower(data_.inputs, predictor_.inverse_squared_lengthscales(), sf2, k, threads);
      if (known.size() > 0) k.diagonal() += known;
    };
    const FactorOutcome outcome = cholesky_with_jitter(n, fill, sf2 + (known.size() > 0 ? known.mean() : 0.0),
                                                       h.noise_variance(), jitter, factor, threads);
    if (outcome.status == FactorStatus::Failed)
      throw std::runtime_error("ExactGpBackend::condition: K is not positive definite even with jitter " +
                               std::to_string(outcome.jitter) + " on " + std::to_string(n) + " points");
    report_.status = outcome.status;
    report_.jitter = outcome.jitter;
    Vector alpha;
    solve_alpha(factor, data_.targets, alpha);
    report_.negative_log_marginal_likelihood = nlml_from_factor(factor, data_.targets, alpha);
    if (n <= kMaxPointsWithCachedInverseFactor) {
      invert_lower_triangular(factor, threads);
      factor.triangularView<Eigen::StrictlyUpper>().setZero();
      predictor_.set_weights(std::move(alpha), std::move(factor), Matrix());
    } else {
      predictor_.set_weights(std::move(alpha), Matrix(), std::move(factor));
    }
  }
  ExactFittedGp(const ExactFittedGp&) = delete;  // predictor_ points into data_
  ExactFittedGp& operator=(const ExactFittedGp&) = delete;

  const ExactPredictor& predictor() const { return predictor_; }

  std::string_view backend_name() const override { return "exact"; }
  int input_dim() const override { return data_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }

  /// The stages of exact_prediction.hpp on this output alone.
  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int d = input_dim();
    if (z.size() != d)
      throw std::invalid_argument("ExactGp::predict: input has " + std::to_string(z.size()) + " entries; expected " +
                                  std::to_string(d));
    PredictionWorkspace& ws = out.workspace;
    ws.cross.resize(data_.size());
    predictor_.cross(z, nullptr, ws.cross);
    out.mean = predictor_.mean(z, ws.cross, request.gradients ? &out.mean_gradient : nullptr, ws.extra);
    if (request.variance)
      out.variance = predictor_.variance(z, ws.cross, request.gradients ? &out.variance_gradient : nullptr,
                                         ws.weighted, ws.extra);
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
        k += predictor_.inverse_squared_lengthscales()(dim) * (data_.inputs.col(dim).array() - points(c, dim)).square();
      k = predictor_.signal_variance() * (-0.5 * k).exp();
    }
    mean.noalias() = cross.transpose() * predictor_.alpha();
    // k*' K^-1 k* = |L^-1 k*|^2 for every point at once: one BLAS-3 triangular product (cached
    // L^-1) or solve (L) with `count` right-hand sides.
    if (predictor_.inverse_factor().size() != 0) {
      solved = cross;
      blas::multiply_lower(blas::Side::Left, blas::Transpose::No, predictor_.inverse_factor(), solved);
      variance = solved.colwise().squaredNorm().transpose();
    } else {
      blas::solve_lower(blas::Side::Left, blas::Transpose::No, predictor_.factor(), cross);
      variance = cross.colwise().squaredNorm().transpose();
    }
    variance = (predictor_.signal_variance() - variance.array()).max(0.0).matrix();
  }

  TrainingSet data_;
  int threads_;
  Vector parameters_;
  ConditioningReport report_;
  ExactPredictor predictor_;  // L^-1 cached when N <= kMaxPointsWithCachedInverseFactor, else L
};

}  // namespace

void ExactPredictor::squared_differences(const Matrix& inputs, const VectorCRef& z, Matrix& squared) {
  squared.resize(inputs.rows(), inputs.cols());
  for (Eigen::Index dim = 0; dim < inputs.cols(); ++dim)
    squared.col(dim).array() = (inputs.col(dim).array() - z(dim)).square();
}

void ExactPredictor::cross(const VectorCRef& z, const Matrix* squared, Eigen::Ref<Vector> k) const {
  const Matrix& x = *inputs_;
  auto a = k.array();
  a.setZero();
  for (Eigen::Index dim = 0; dim < x.cols(); ++dim) {
    if (squared != nullptr)
      a += w_(dim) * squared->col(dim).array();
    else
      a += w_(dim) * (x.col(dim).array() - z(dim)).square();
  }
  a = sf2_ * (-0.5 * a).exp();
}

double ExactPredictor::mean(const VectorCRef& z, const VectorCRef& k, Vector* gradient, Vector& scratch) const {
  const double m = k.dot(alpha_);
  if (gradient != nullptr) {
    const Matrix& x = *inputs_;
    scratch.resize(x.rows());
    scratch.array() = alpha_.array() * k.array();
    gradient->resize(x.cols());
    for (Eigen::Index dim = 0; dim < x.cols(); ++dim)
      (*gradient)(dim) = w_(dim) * (x.col(dim).dot(scratch) - z(dim) * m);
  }
  return m;
}

double ExactPredictor::variance(const VectorCRef& z, const VectorCRef& k, Vector* gradient, Vector& weighted,
                                Vector& scratch) const {
  const Matrix& x = *inputs_;
  const Eigen::Index n = x.rows();
  weighted.resize(n);
  scratch.resize(n);
  double explained = 0.0;  // k' K^-1 k
  if (inverse_factor_.size() != 0) {
    weighted.noalias() = inverse_factor_.triangularView<Eigen::Lower>() * k;
    explained = weighted.squaredNorm();
    if (gradient != nullptr) {
      scratch.noalias() = inverse_factor_.triangularView<Eigen::Lower>().transpose() * weighted;
      weighted.swap(scratch);
    }
  } else {
    weighted = k;
    factor_.triangularView<Eigen::Lower>().solveInPlace(weighted);
    explained = weighted.squaredNorm();
    if (gradient != nullptr) factor_.triangularView<Eigen::Lower>().adjoint().solveInPlace(weighted);
  }
  if (gradient != nullptr) {
    scratch.array() = weighted.array() * k.array();
    gradient->resize(x.cols());
    for (Eigen::Index dim = 0; dim < x.cols(); ++dim)
      (*gradient)(dim) = -2.0 * w_(dim) * (x.col(dim).dot(scratch) - z(dim) * explained);
  }
  return std::max(sf2_ - explained, 0.0);
}

const ExactPredictor* exact_predictor(const FittedGp& gp) {
  const auto* exact = dynamic_cast<const ExactFittedGp*>(&gp);
  return exact != nullptr ? &exact->predictor() : nullptr;
}

std::unique_ptr<FittedGp> make_exact_fitted_gp(TrainingSet data, const VectorCRef& parameters,
                                               const JitterSchedule& jitter, int threads) {
  return std::make_unique<ExactFittedGp>(std::move(data), parameters, jitter, threads);
}

}  // namespace gpilqg::gp::detail
