#include "gp_estimator.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace gpilqg::python {

void GpConfig::validate() const {
  (void)gp::make_backend(backend, settings);  // unknown name or bad sizes: the registry's message
  fit.validate();
}

GpState::GpState(GpConfig config, gp::FitResult result)
    : config_(std::move(config)), model_(std::move(result.model)), summary_(std::move(result.summary)) {}

int GpState::extra_rows() const {
  const int d = model_->input_dim();
  return static_cast<int>(model_->parameters().size() - gp::Hyperparameters::count(d)) / d;
}

double GpState::log_marginal_likelihood(const VectorCRef& theta, Vector* gradient) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!objective_) {
    // The objective for the model's own extras count (FITC's M, SSGP's m), which min(M, N) or a
    // theta given to fit() may have set differently from the settings.
    gp::BackendSettings settings = config_.settings;
    if (extra_rows() > 0) settings.inducing = settings.frequencies = extra_rows();
    objective_ = gp::make_backend(config_.backend, settings)->objective(model_->training_set(), config_.fit);
  }
  if (theta.size() != objective_->parameter_count())
    throw std::invalid_argument("GaussianProcess.log_marginal_likelihood: theta has " + std::to_string(theta.size()) +
                                " entries; the " + config_.backend + " model has " +
                                std::to_string(objective_->parameter_count()));
  const gp::NlmlEvaluation evaluation = objective_->evaluate(theta, gradient);
  if (evaluation.status == gp::FactorStatus::Failed) {
    if (gradient != nullptr) gradient->setZero(theta.size());
    return -std::numeric_limits<double>::infinity();
  }
  if (gradient != nullptr) *gradient = -*gradient;
  return -evaluation.value;
}

std::shared_ptr<const GpState> fit_gp(const GpConfig& config, gp::TrainingSet data,
                                      const std::optional<Vector>& theta) {
  const auto backend = gp::make_backend(config.backend, config.settings);
  if (!theta) return std::make_shared<const GpState>(config, backend->fit(data, config.fit));

  const std::string who = "GaussianProcess(" + config.backend + ").fit";
  gp::validate_training_set(data, who);
  gp::TrainingSet selected = backend->select_training_points(data, config.fit.seed);
  gp::FitResult result;
  result.summary.backend = config.backend;
  result.summary.training_points = selected.size();
  result.summary.parameters = static_cast<int>(theta->size());
  result.summary.termination = gp::FitTermination::NotOptimised;
  result.model = backend->condition(std::move(selected), *theta, config.fit.jitter);
  result.summary.conditioning = result.model->conditioning();
  result.summary.initial_nlml = result.summary.nlml = result.summary.conditioning.negative_log_marginal_likelihood;
  return std::make_shared<const GpState>(config, std::move(result));
}

void predict_gp(const gp::FittedGp& model, const MatrixCRef& points, const PredictionBuffers& out) {
  if (points.cols() != model.input_dim())
    throw std::invalid_argument("GaussianProcess.predict: X has " + std::to_string(points.cols()) +
                                " columns; the model was fitted to D = " + std::to_string(model.input_dim()));
  const Eigen::Index n = points.rows();
  const Eigen::Index d = points.cols();
  const bool gradients = out.mean_gradient != nullptr;
  if (!gradients && out.std != nullptr) {  // the backends' blocked batch prediction
    Vector mean;
    Vector variance;
    model.predict(points, mean, variance);
    for (Eigen::Index i = 0; i < n; ++i) {
      out.mean[i] = mean(i);
      out.std[i] = std::sqrt(variance(i));
    }
    return;
  }
  gp::PredictionRequest request;
  request.variance = out.std != nullptr;
  request.gradients = gradients;
  gp::Prediction p;
  Vector z(d);
  for (Eigen::Index i = 0; i < n; ++i) {
    z = points.row(i).transpose();
    model.predict(z, p, request);
    out.mean[i] = p.mean;
    if (out.std != nullptr) out.std[i] = std::sqrt(p.variance);
    if (!gradients) continue;
    for (Eigen::Index j = 0; j < d; ++j) out.mean_gradient[i * d + j] = p.mean_gradient(j);
    if (out.std_gradient == nullptr) continue;
    const double s = out.std[i];
    for (Eigen::Index j = 0; j < d; ++j)
      out.std_gradient[i * d + j] = s > 0.0 ? p.variance_gradient(j) / (2.0 * s) : 0.0;
  }
}

}  // namespace gpilqg::python
