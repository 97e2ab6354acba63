/// The SSGP backend behind the GpBackend interface: options, the NLML objective (bounds and the
/// best-of-many random initialisation of the spectral points) and the fitted model.

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "gpilqg/gp/hyperparameters.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "sparse_backend.hpp"

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

struct SsgpTraits {
  using Likelihood = SsgpLikelihood;
  using Predictor = SsgpPredictor;
  using Layout = SsgpLayout;
  static constexpr std::string_view name = "ssgp";
  static constexpr const char* label = "SSGP";
  static constexpr const char* condition_who = "SsgpBackend::condition";
  static int cross_size(const SsgpPredictor& p) { return 2 * p.frequencies(); }
  static void predict(const SsgpPredictor& p, const VectorCRef& z, PredictionWorkspace& w, double& mean,
                      double* variance, double* dmean, double* dvariance) {
    p.predict(z, w.cross.data(), w.weighted.data(), mean, variance, dmean, dvariance);
  }
};

/// The start of an SSGP fit: the data-driven hyperparameters with the best of `initial_draws` draws
/// W ~ N(0, I) (as ssgpr_ui); the hyperparameter box, the spectral points unbounded.
std::pair<Vector, ParameterBounds> ssgp_start(const SsgpLikelihood& likelihood, const TrainingSet& data,
                                              const SsgpOptions& ssgp, const FitOptions& fit) {
  const SsgpLayout& layout = likelihood.layout();
  const int D = layout.input_dim;
  const Vector hyper = initial_hyperparameters(data).pack();
  std::mt19937_64 rng(fit.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  double best = std::numeric_limits<double>::infinity();
  Vector initial;
  Matrix W(layout.frequencies, D);
  const auto workspace = likelihood.make_workspace();
  for (int k = 0; k < ssgp.initial_draws; ++k) {
    for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = normal(rng);
    const Vector theta = layout.pack(hyper, W);
    const double value = likelihood.evaluate(theta, nullptr, *workspace).value;
    if (value < best || initial.size() == 0) {
      best = value;
      initial = theta;
    }
  }
  const ParameterBounds hb = hyperparameter_bounds(data, fit.min_noise_std);
  const double inf = std::numeric_limits<double>::infinity();
  ParameterBounds bounds{Vector::Constant(layout.size(), -inf), Vector::Constant(layout.size(), inf)};
  bounds.lower.head(D + 2) = hb.lower;
  bounds.upper.head(D + 2) = hb.upper;
  return {std::move(initial), std::move(bounds)};
}

}  // namespace

const SsgpPredictor* ssgp_posterior(const FittedGp& model) {
  return sparse_detail::posterior_of<SsgpTraits>(model);
}

SsgpBackend::SsgpBackend(SsgpOptions options) : options_(std::move(options)) { options_.validate(); }

std::unique_ptr<MarginalLikelihoodObjective> SsgpBackend::objective(const TrainingSet& data,
                                                                    const FitOptions& options) const {
  validate_training_set(data, "SsgpBackend::objective");
  options.validate();
  SsgpLikelihood likelihood(data.inputs, data.targets, options_.frequencies, options.jitter, options_.threads,
                            data.noise_variance);
  auto [initial, bounds] = ssgp_start(likelihood, data, options_, options);
  return std::make_unique<sparse_detail::LikelihoodObjective<SsgpLikelihood>>(std::move(likelihood),
                                                                              std::move(initial), std::move(bounds));
}

std::unique_ptr<FittedGp> SsgpBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                 const JitterSchedule& jitter) const {
  return sparse_detail::condition<SsgpTraits>(
      std::move(data), parameters, jitter, [&](const SsgpLayout& layout, const TrainingSet& d) {
        return SsgpLikelihood(d.inputs, d.targets, layout.frequencies, jitter, options_.threads, d.noise_variance);
      });
}

}  // namespace gpilqg::gp
