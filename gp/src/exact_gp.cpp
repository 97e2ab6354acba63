#include "gpilqg/gp/exact_gp.hpp"

#include <stdexcept>
#include <string>

#include "exact_gp_internal.hpp"

namespace gpilqg::gp {

void ExactGpOptions::validate() const {
  if (max_training_points < 1)
    throw std::invalid_argument("ExactGpOptions::max_training_points = " + std::to_string(max_training_points) +
                                "; expected >= 1 (ExactGpOptions::kAllPoints for all points)");
  if (threads < 1)
    throw std::invalid_argument("ExactGpOptions::threads = " + std::to_string(threads) + "; expected >= 1");
}

ExactGpBackend::ExactGpBackend(ExactGpOptions options) : options_(options) { options_.validate(); }

TrainingSet ExactGpBackend::select_training_points(const TrainingSet& data, std::uint64_t seed) const {
  if (data.size() <= options_.max_training_points) return data;
  return data.subset(uniform_subsample(data.size(), options_.max_training_points, seed));
}

std::unique_ptr<MarginalLikelihoodObjective> ExactGpBackend::objective(const TrainingSet& data,
                                                                       const FitOptions& options) const {
  validate_training_set(data, "ExactGpBackend::objective");
  options.validate();
  return detail::make_exact_objective(data, options, options_.threads);
}

std::unique_ptr<FittedGp> ExactGpBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                    const JitterSchedule& jitter) const {
  validate_training_set(data, "ExactGpBackend::condition");
  jitter.validate();
  return detail::make_exact_fitted_gp(std::move(data), parameters, jitter, options_.threads);
}

}  // namespace gpilqg::gp
