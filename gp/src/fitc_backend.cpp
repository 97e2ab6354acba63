/// The FITC backend behind the GpBackend interface: options, the NLML objective (bounds and initial
/// values) and the fitted model.

#include <algorithm>
#include <cmath>
#include <utility>
#include <stdexcept>
#include <string>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/hyperparameters.hpp"
#include "sparse_backend.hpp"

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

struct FitcTraits {
  using Likelihood = FitcLikelihood;
  using Predictor = FitcPredictor;
  using Layout = FitcLayout;
  static constexpr std::string_view name = "fitc";
  static constexpr const char* label = "FITC";
  static constexpr const char* condition_who = "FitcBackend::condition";
  static int cross_size(const FitcPredictor& p) { return p.inducing(); }
  static void predict(const FitcPredictor& p, const VectorCRef& z, PredictionWorkspace& w, double& mean,
                      double* variance, double* dmean, double* dvariance) {
    if (w.extra.size() != p.input_dim()) w.extra.resize(p.input_dim());
    p.predict(z, w.cross.data(), w.weighted.data(), w.extra.data(), mean, variance, dmean, dvariance);
  }
};

/// The start (data-driven hyperparameters, pseudo-inputs by fitc.initialisation) and the bounds of a
/// FITC fit: the hyperparameter box, and each pseudo-input coordinate within the data's range widened by
/// that range on both sides (or pinned at its start when the pseudo-inputs are not optimised).
std::pair<Vector, ParameterBounds> fitc_start(const FitcLayout& layout, const TrainingSet& data,
                                              const FitcOptions& fitc, const FitOptions& fit) {
  const int D = layout.input_dim;
  const Hyperparameters h = initial_hyperparameters(data);
  const Matrix Xu = initial_pseudo_inputs(data.inputs, layout.inducing, h.lengthscales(), fitc.initialisation,
                                          fit.seed, fitc.kmeans_iterations);
  Vector initial = layout.pack(h.pack(), Xu);
  ParameterBounds bounds;
  const ParameterBounds hb = hyperparameter_bounds(data, fit.min_noise_std);
  bounds.lower.resize(layout.size());
  bounds.upper.resize(layout.size());
  bounds.lower.head(D + 2) = hb.lower;
  bounds.upper.head(D + 2) = hb.upper;
  if (fitc.optimise_pseudo_inputs) {
    const Vector lo = data.inputs.colwise().minCoeff().transpose();
    const Vector hi = data.inputs.colwise().maxCoeff().transpose();
    for (int d = 0; d < D; ++d) {
      const double range = hi(d) > lo(d) ? hi(d) - lo(d) : 1.0;
      bounds.lower.segment(layout.inducing_offset() + d * layout.inducing, layout.inducing).setConstant(lo(d) - range);
      bounds.upper.segment(layout.inducing_offset() + d * layout.inducing, layout.inducing).setConstant(hi(d) + range);
    }
  } else {
    bounds.lower.tail(layout.size() - D - 2) = initial.tail(layout.size() - D - 2);
    bounds.upper.tail(layout.size() - D - 2) = initial.tail(layout.size() - D - 2);
  }
  return {std::move(initial), std::move(bounds)};
}

}  // namespace

const FitcPredictor* fitc_posterior(const FittedGp& model) {
  return sparse_detail::posterior_of<FitcTraits>(model);
}

FitcBackend::FitcBackend(FitcOptions options) : options_(std::move(options)) { options_.validate(); }

std::unique_ptr<MarginalLikelihoodObjective> FitcBackend::objective(const TrainingSet& data,
                                                                    const FitOptions& options) const {
  validate_training_set(data, "FitcBackend::objective");
  options.validate();
  FitcLikelihood likelihood(data.inputs, data.targets, std::min(options_.inducing, data.size()), options_.jitter,
                            options.jitter, options_.threads, data.noise_variance);
  auto [initial, bounds] = fitc_start(likelihood.layout(), data, options_, options);
  return std::make_unique<sparse_detail::LikelihoodObjective<FitcLikelihood>>(std::move(likelihood),
                                                                              std::move(initial), std::move(bounds));
}

std::unique_ptr<FittedGp> FitcBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter) const {
  return sparse_detail::condition<FitcTraits>(
      std::move(data), parameters, jitter, [&](const FitcLayout& layout, const TrainingSet& d) {
        return FitcLikelihood(d.inputs, d.targets, layout.inducing, options_.jitter, jitter, options_.threads,
                              d.noise_variance);
      });
}

}  // namespace gpilqg::gp
