/// The FITC backend behind the GpBackend interface: options, the NLML objective (bounds and initial
/// values) and the fitted model.

#include <cmath>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::gp {

void FitcOptions::validate() const {
  if (inducing < 1)
    throw std::invalid_argument("FitcOptions::inducing = " + std::to_string(inducing) + "; expected >= 1");
  if (threads < 1)
    throw std::invalid_argument("FitcOptions::threads = " + std::to_string(threads) + "; expected >= 1");
  if (kmeans_iterations < 0)
    throw std::invalid_argument("FitcOptions::kmeans_iterations = " + std::to_string(kmeans_iterations) +
                                "; expected >= 0");
  if (!std::isfinite(jitter.value) || jitter.value < 0.0)
    throw std::invalid_argument("FitcOptions::jitter.value = " + std::to_string(jitter.value) +
                                "; expected finite and >= 0");
}

namespace {

class FitcObjective final : public MarginalLikelihoodObjective {
 public:
  FitcObjective(const TrainingSet& data, const FitcOptions& fitc, const FitOptions& fit)
      : likelihood_(data.inputs, data.targets, std::min(fitc.inducing, data.size()), fitc.jitter, fit.jitter,
                    fitc.threads) {
    const FitcLayout& layout = likelihood_.layout();
    const int D = layout.input_dim;
    const Hyperparameters h = initial_hyperparameters(data);
    const Matrix Xu = initial_pseudo_inputs(data.inputs, layout.inducing, h.lengthscales(),
                                            fitc.initialisation, fit.seed, fitc.kmeans_iterations);
    initial_ = layout.pack(h.pack(), Xu);

    const ParameterBounds hb = hyperparameter_bounds(data, fit.min_noise_std);
    bounds_.lower.resize(layout.size());
    bounds_.upper.resize(layout.size());
    bounds_.lower.head(D + 2) = hb.lower;
    bounds_.upper.head(D + 2) = hb.upper;
    if (fitc.optimise_pseudo_inputs) {
      // Each coordinate within the data's range widened by that range on both sides.
      const Vector lo = data.inputs.colwise().minCoeff().transpose();
      const Vector hi = data.inputs.colwise().maxCoeff().transpose();
      for (int d = 0; d < D; ++d) {
        const double range = hi(d) > lo(d) ? hi(d) - lo(d) : 1.0;
        bounds_.lower.segment(layout.inducing_offset() + d * layout.inducing, layout.inducing)
            .setConstant(lo(d) - range);
        bounds_.upper.segment(layout.inducing_offset() + d * layout.inducing, layout.inducing)
            .setConstant(hi(d) + range);
      }
    } else {
      bounds_.lower.tail(layout.size() - D - 2) = initial_.tail(layout.size() - D - 2);
      bounds_.upper.tail(layout.size() - D - 2) = initial_.tail(layout.size() - D - 2);
    }
  }

  int parameter_count() const override { return likelihood_.parameter_count(); }
  int input_dim() const override { return likelihood_.layout().input_dim; }
  NlmlEvaluation evaluate(const VectorCRef& parameters, Vector* gradient) override {
    return likelihood_.evaluate(parameters, gradient);
  }
  ParameterBounds bounds() const override { return bounds_; }
  Vector initial_parameters() const override { return initial_; }

 private:
  FitcLikelihood likelihood_;
  Vector initial_;
  ParameterBounds bounds_;
};

class FittedFitc final : public FittedGp {
 public:
  FittedFitc(TrainingSet data, Vector parameters, FitcPredictor predictor, ConditioningReport report)
      : data_(std::move(data)),
        parameters_(std::move(parameters)),
        predictor_(std::move(predictor)),
        report_(report) {}

  std::string_view backend_name() const override { return "fitc"; }
  int input_dim() const override { return predictor_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }

  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int D = predictor_.input_dim();
    const int M = predictor_.inducing();
    if (z.size() != D)
      throw std::invalid_argument("FITC prediction: the input has " + std::to_string(z.size()) +
                                  " entries; expected " + std::to_string(D));
    PredictionWorkspace& w = out.workspace;
    if (w.cross.size() != M) w.cross.resize(M);
    if (w.weighted.size() != M) w.weighted.resize(M);
    if (w.extra.size() != D) w.extra.resize(D);
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
    predictor_.predict(z, w.cross.data(), w.weighted.data(), w.extra.data(), out.mean,
                       request.variance ? &out.variance : nullptr, dmean, dvariance);
  }

 private:
  TrainingSet data_;
  Vector parameters_;
  FitcPredictor predictor_;
  ConditioningReport report_;
};

}  // namespace

FitcBackend::FitcBackend(FitcOptions options) : options_(std::move(options)) { options_.validate(); }

std::unique_ptr<MarginalLikelihoodObjective> FitcBackend::objective(const TrainingSet& data,
                                                                    const FitOptions& options) const {
  validate_training_set(data, "FitcBackend::objective");
  options.validate();
  return std::make_unique<FitcObjective>(data, options_, options);
}

std::unique_ptr<FittedGp> FitcBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter) const {
  validate_training_set(data, "FitcBackend::condition");
  jitter.validate();
  const FitcLayout layout = FitcLayout::from_size(static_cast<int>(parameters.size()), data.input_dim());
  if (!parameters.allFinite())
    throw std::invalid_argument("FitcBackend::condition: the parameter vector has non-finite entries");
  const FitcLikelihood likelihood(data.inputs, data.targets, layout.inducing, options_.jitter, jitter,
                                  options_.threads);
  ConditioningReport report;
  FitcPredictor predictor = likelihood.predictor(parameters, &report);
  return std::make_unique<FittedFitc>(std::move(data), Vector(parameters), std::move(predictor), report);
}

}  // namespace gpilqg::gp
