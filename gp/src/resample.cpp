#include "gpilqg/gp/resample.hpp"

#include <sstream>
#include <stdexcept>

namespace gpilqg::gp {

void ResampleOptions::validate() const {
  if (max_resamples < 0)
    throw std::invalid_argument("ResampleOptions::max_resamples = " + std::to_string(max_resamples) +
                                "; expected >= 0");
}

std::string ResampleReport::one_line() const {
  std::ostringstream os;
  os << validation_mse.size() << " attempt(s), validation MSE";
  for (double e : validation_mse) os << " " << e;
  os << "; chose attempt " << chosen_attempt;
  if (previous_validation_mse >= 0.0)
    os << (improved ? ", no worse than" : ", WORSE than") << " the previous learner's " << previous_validation_mse;
  return os.str();
}

double validation_mse(const FittedGp& model, const TrainingSet& validation) {
  if (validation.size() == 0) throw std::invalid_argument("validation_mse: empty validation set");
  if (validation.input_dim() != model.input_dim() || validation.targets.size() != validation.size())
    throw std::invalid_argument("validation_mse: validation set has " + std::to_string(validation.input_dim()) +
                                " inputs and " + std::to_string(validation.targets.size()) +
                                " targets; expected " + std::to_string(model.input_dim()) +
                                " inputs and one target per row");
  Vector mean, variance;
  model.predict(validation.inputs, mean, variance);
  return (mean - validation.targets).squaredNorm() / static_cast<double>(validation.size());
}

FitResult fit_with_resampling(const GpBackend& backend, const TrainingSet& data, const TrainingSet& validation,
                              const FittedGp* previous, const FitOptions& options, const ResampleOptions& resample,
                              ResampleReport* report) {
  resample.validate();
  ResampleReport local;
  ResampleReport& r = report != nullptr ? *report : local;
  r = ResampleReport{};
  if (previous != nullptr) r.previous_validation_mse = validation_mse(*previous, validation);
  FitResult best;
  double best_error = 0.0;
  for (int attempt = 0; attempt <= resample.max_resamples; ++attempt) {
    FitOptions attempt_options = options;
    attempt_options.seed = options.seed + static_cast<std::uint64_t>(attempt);
    FitResult result = backend.fit(data, attempt_options);
    const double error = validation_mse(*result.model, validation);
    r.validation_mse.push_back(error);
    if (attempt == 0 || error < best_error) {
      best = std::move(result);
      best_error = error;
      r.chosen_attempt = attempt;
    }
    if (previous == nullptr || best_error <= r.previous_validation_mse) break;
  }
  r.improved = previous == nullptr || best_error <= r.previous_validation_mse;
  return best;
}

}  // namespace gpilqg::gp
