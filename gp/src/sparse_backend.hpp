#pragma once
/// @file sparse_backend.hpp
/// What the FITC and SSGP backends (fitc_backend.cpp, ssgp_backend.cpp) share behind the GpBackend
/// interface: the NLML objective around their likelihood class, the fitted model around their
/// predictor class, and conditioning. A backend supplies a traits struct:
///
///   struct Traits {
///     using Likelihood = ...;  using Predictor = ...;  using Layout = ...;
///     static constexpr std::string_view name;     // registry name ("fitc")
///     static constexpr const char* label;         // for messages ("FITC")
///     static constexpr const char* condition_who; // "FitcBackend::condition"
///     static int cross_size(const Predictor&);    // entries of k (FITC: M, SSGP: 2m features)
///     static void predict(const Predictor&, const VectorCRef& z, PredictionWorkspace&, double& mean,
///                         double* variance, double* dmean, double* dvariance);
///   };
///
/// Traits::predict receives the workspace with `cross` and `weighted` sized to cross_size.

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "gpilqg/gp/backend.hpp"

namespace gpilqg::gp::sparse_detail {

/// The NLML of one data set through the backend's likelihood class, evaluated in the objective's own
/// workspace (as the exact GP's objective holds its matrices); the backend fixes the start and the
/// bounds when it builds the objective.
template <class Likelihood>
class LikelihoodObjective final : public MarginalLikelihoodObjective {
 public:
  LikelihoodObjective(Likelihood likelihood, Vector initial, ParameterBounds bounds)
      : likelihood_(std::move(likelihood)),
        workspace_(likelihood_.make_workspace()),
        initial_(std::move(initial)),
        bounds_(std::move(bounds)) {}

  int parameter_count() const override { return likelihood_.parameter_count(); }
  int input_dim() const override { return likelihood_.layout().input_dim; }
  NlmlEvaluation evaluate(const VectorCRef& parameters, Vector* gradient) override {
    return likelihood_.evaluate(parameters, gradient, *workspace_);
  }
  ParameterBounds bounds() const override { return bounds_; }
  Vector initial_parameters() const override { return initial_; }

 private:
  Likelihood likelihood_;
  std::unique_ptr<LikelihoodWorkspace> workspace_;
  Vector initial_;
  ParameterBounds bounds_;
};

/// A conditioned sparse GP: the training set, the parameters, the cached predictor.
template <class Traits>
class FittedSparseGp final : public FittedGp {
 public:
  using Predictor = typename Traits::Predictor;
  FittedSparseGp(TrainingSet data, Vector parameters, Predictor predictor, ConditioningReport report)
      : data_(std::move(data)),
        parameters_(std::move(parameters)),
        predictor_(std::move(predictor)),
        report_(report) {}

  std::string_view backend_name() const override { return Traits::name; }
  int input_dim() const override { return predictor_.input_dim(); }
  const TrainingSet& training_set() const override { return data_; }
  const Vector& parameters() const override { return parameters_; }
  const ConditioningReport& conditioning() const override { return report_; }
  /// The cached posterior (fitc_posterior / ssgp_posterior hand it out).
  const Predictor& predictor() const { return predictor_; }

  void predict(const VectorCRef& z, Prediction& out, const PredictionRequest& request) const override {
    const int D = predictor_.input_dim();
    if (z.size() != D)
      throw std::invalid_argument(std::string(Traits::label) + " prediction: the input has " +
                                  std::to_string(z.size()) + " entries; expected " + std::to_string(D));
    const int size = Traits::cross_size(predictor_);
    PredictionWorkspace& w = out.workspace;
    if (w.cross.size() != size) w.cross.resize(size);
    if (w.weighted.size() != size) w.weighted.resize(size);
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
    Traits::predict(predictor_, z, w, out.mean, request.variance ? &out.variance : nullptr, dmean,
                    dvariance);
  }

 private:
  TrainingSet data_;
  Vector parameters_;
  Predictor predictor_;
  ConditioningReport report_;
};

/// The cached predictor of `model` when it is a FittedSparseGp<Traits>, else nullptr.
template <class Traits>
const typename Traits::Predictor* posterior_of(const FittedGp& model) {
  const auto* fitted = dynamic_cast<const FittedSparseGp<Traits>*>(&model);
  return fitted != nullptr ? &fitted->predictor() : nullptr;
}

/// GpBackend::condition for a sparse backend: checks the data, the jitter schedule, the size
/// (Layout::from_size) and finiteness of the parameters, then conditions through the likelihood that
/// `make_likelihood(layout)` builds.
template <class Traits, class MakeLikelihood>
std::unique_ptr<FittedGp> condition(TrainingSet data, const VectorCRef& parameters, const JitterSchedule& jitter,
                                    MakeLikelihood&& make_likelihood) {
  validate_training_set(data, Traits::condition_who);
  jitter.validate();
  const auto layout = Traits::Layout::from_size(static_cast<int>(parameters.size()), data.input_dim());
  if (!parameters.allFinite())
    throw std::invalid_argument(std::string(Traits::condition_who) + ": the parameter vector has non-finite entries");
  const typename Traits::Likelihood likelihood = make_likelihood(layout, data);
  ConditioningReport report;
  typename Traits::Predictor predictor = likelihood.predictor(parameters, &report);
  return std::make_unique<FittedSparseGp<Traits>>(std::move(data), Vector(parameters), std::move(predictor), report);
}

}  // namespace gpilqg::gp::sparse_detail
