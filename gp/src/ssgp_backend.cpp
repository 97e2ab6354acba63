/// The SSGP backend behind the GpBackend interface: options, the NLML objective (bounds and the
/// best-of-many random initialisation of the spectral points) and the fitted model.

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/hyperparameters.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace gpilqg::gp {

void SsgpOptions::validate() const {
  if (frequencies < 1)
    throw std::invalid_argument("SsgpOptions::frequencies = " + std::to_string(frequencies) +
                                "; expected >= 1");
  if (threads < 1)
    throw std::invalid_argument("SsgpOptions::threads = " + std::to_string(threads) + "; expected >= 1");
  if (initial_draws < 1)
    throw std::invalid_argument("SsgpOptions::initial_draws = " + std::to_string(initial_draws) +
                                "; expected >= 1");
}

namespace {

class SsgpObjective final : public MarginalLikelihoodObjective {
 public:
  SsgpObjective(const TrainingSet& data, const SsgpOptions& ssgp, const FitOptions& fit)
      : likelihood_(data.inputs, data.targets, ssgp.frequencies, fit.jitter, ssgp.threads) {
    const SsgpLayout& layout = likelihood_.layout();
    const int D = layout.input_dim;
    const Vector hyper = initial_hyperparameters(data).pack();
    // The best of `initial_draws` draws W ~ N(0, I) at the initial hyperparameters (as ssgpr_ui).
    std::mt19937_64 rng(fit.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    double best = std::numeric_limits<double>::infinity();
    Matrix W(layout.frequencies, D);
    for (int k = 0; k < ssgp.initial_draws; ++k) {
      for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = normal(rng);
      const Vector theta = layout.pack(hyper, W);
      const double value = likelihood_.evaluate(theta).value;
      if (value < best || initial_.size() == 0) {
        best = value;
        initial_ = theta;
      }
    }
    const ParameterBounds hb = hyperparameter_bounds(data, fit.min_noise_std);
    const double inf = std::numeric_limits<double>::infinity();
    bounds_.lower = Vector::Constant(layout.size(), -inf);
    bounds_.upper = Vector::Constant(layout.size(), inf);
    bounds_.lower.head(D + 2) = hb.lower;
    bounds_.upper.head(D + 2) = hb.upper;
  }

  int parameter_count() const override { return likelihood_.parameter_count(); }
  int input_dim() const override { return likelihood_.layout().input_dim; }
  NlmlEvaluation evaluate(const VectorCRef& parameters, Vector* gradient) override {
    return likelihood_.evaluate(parameters, gradient);
  }
  ParameterBounds bounds() const override { return bounds_; }
  Vector initial_parameters() const override { return initial_; }

 private:
  SsgpLikelihood likelihood_;
  Vector initial_;
  ParameterBounds bounds_;
};

class FittedSsgp final : public FittedGp {
 public:
  FittedSsgp(TrainingSet data, Vector parameters, SsgpPredictor predictor, ConditioningReport report)
      : data_(std::move(data)),
        parameters_(std::move(parameters)),
        predictor_(std::move(predictor)),
        report_(report) {}

  std::string_view backend_name() const override { return "ssgp"; }
  int input_dim() const override { return predictor_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }

  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int D = predictor_.input_dim();
    const int features = 2 * predictor_.frequencies();
    if (z.size() != D)
      throw std::invalid_argument("SSGP prediction: the input has " + std::to_string(z.size()) +
                                  " entries; expected " + std::to_string(D));
    PredictionWorkspace& w = out.workspace;
    if (w.cross.size() != features) w.cross.resize(features);
    if (w.weighted.size() != features) w.weighted.resize(features);
    double* dmean = nullptr;
    double* dvariance = nullptr;
    if (request.gradients) {
      if (out.mean_gradient.size() != D) out.mean_gradient.resize(D);
      dmean = out.mean_gradient.data();
      if (request.variance) {
        if (out.variance_gradient.size() != D) out.variance_gradient.resize(D);
        dvariance = out.variance_gradient.data();
      }
    }
    predictor_.predict(z, w.cross.data(), w.weighted.data(), out.mean,
                       request.variance ? &out.variance : nullptr, dmean, dvariance);
  }

 private:
  TrainingSet data_;
  Vector parameters_;
  SsgpPredictor predictor_;
  ConditioningReport report_;
};

}  // namespace

SsgpBackend::SsgpBackend(SsgpOptions options) : options_(std::move(options)) { options_.validate(); }

std::unique_ptr<MarginalLikelihoodObjective> SsgpBackend::objective(const TrainingSet& data,
                                                                    const FitOptions& options) const {
  validate_training_set(data, "SsgpBackend::objective");
  options.validate();
  return std::make_unique<SsgpObjective>(data, options_, options);
}

std::unique_ptr<FittedGp> SsgpBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter) const {
  validate_training_set(data, "SsgpBackend::condition");
  jitter.validate();
  const SsgpLayout layout = SsgpLayout::from_size(static_cast<int>(parameters.size()), data.input_dim());
  if (!parameters.allFinite())
    throw std::invalid_argument("SsgpBackend::condition: the parameter vector has non-finite entries");
  const SsgpLikelihood likelihood(data.inputs, data.targets, layout.frequencies, jitter, options_.threads);
  ConditioningReport report;
  SsgpPredictor predictor = likelihood.predictor(parameters, &report);
  return std::make_unique<FittedSsgp>(std::move(data), Vector(parameters), std::move(predictor), report);
}

}  // namespace gpilqg::gp
