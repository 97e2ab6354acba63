#include "gpilqg/gp/backend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "gpilqg/gp/fit.hpp"

namespace gpilqg::gp {

std::string_view to_string(FactorStatus status) {
  switch (status) {
    case FactorStatus::Ok: return "ok";
    case FactorStatus::JitterAdded: return "jitter added";
    case FactorStatus::Failed: return "failed";
  }
  return "unknown";
}

std::string_view to_string(FitTermination termination) {
  switch (termination) {
    case FitTermination::Converged: return "converged";
    case FitTermination::MaxEvaluations: return "evaluation limit reached";
    case FitTermination::NotOptimised: return "not optimised";
    case FitTermination::OptimiserError: return "optimiser error";
    case FitTermination::TimeLimit: return "time limit reached";
  }
  return "unknown";
}

void JitterSchedule::validate() const {
  if (!(first > 0.0) || !(last >= first) || !std::isfinite(last) || !(growth > 1.0) || !std::isfinite(growth)) {
    std::ostringstream os;
    os << "JitterSchedule: first = " << first << ", last = " << last << ", growth = " << growth
       << "; expected 0 < first <= last (finite) and growth > 1";
    throw std::invalid_argument(os.str());
  }
}

void FitOptions::validate() const {
  auto fail = [](const std::string& field, const std::string& value, const std::string& expected) {
    throw std::invalid_argument("FitOptions::" + field + " = " + value + "; expected " + expected);
  };
  if (restarts < 0) fail("restarts", std::to_string(restarts), ">= 0");
  if (max_evaluations < 1) fail("max_evaluations", std::to_string(max_evaluations), ">= 1");
  if (!(relative_tolerance >= 0.0) || !std::isfinite(relative_tolerance))
    fail("relative_tolerance", std::to_string(relative_tolerance), "finite and >= 0");
  if (!(parameter_tolerance >= 0.0) || !std::isfinite(parameter_tolerance))
    fail("parameter_tolerance", std::to_string(parameter_tolerance), "finite and >= 0");
  if (!(min_noise_std > 0.0) || !std::isfinite(min_noise_std))
    fail("min_noise_std", std::to_string(min_noise_std), "finite and > 0");
  if (!(min_noise_ratio >= 0.0) || !std::isfinite(min_noise_ratio))
    fail("min_noise_ratio", std::to_string(min_noise_ratio), "finite and >= 0");
  if (!warm_start.allFinite()) fail("warm_start", "a vector with non-finite entries", "finite entries");
  if (!(max_seconds >= 0.0) || !std::isfinite(max_seconds))
    fail("max_seconds", std::to_string(max_seconds), "finite and >= 0 (0: no limit)");
  jitter.validate();
}

std::string FitSummary::one_line() const {
  std::ostringstream os;
  os << backend << ": N=" << training_points << ", " << parameters << " parameters, nlml " << initial_nlml
     << " -> " << nlml << " in " << evaluations << " evaluations (" << starts << " starts, best " << best_start
     << "), " << to_string(termination);
  if (jittered_evaluations > 0 || failed_evaluations > 0)
    os << "; " << jittered_evaluations << " evaluations needed jitter (max " << max_jitter << "), "
       << failed_evaluations << " failed";
  if (conditioning.status != FactorStatus::Ok)
    os << "; final model: " << to_string(conditioning.status) << " " << conditioning.jitter;
  else
    os << "; final model without jitter";
  os << ", " << seconds << " s";
  return os.str();
}

void FittedGp::predict(const MatrixCRef& points, Vector& mean, Vector& variance) const {
  if (points.cols() != input_dim())
    throw std::invalid_argument("FittedGp::predict: points have " + std::to_string(points.cols()) +
                                " columns; expected " + std::to_string(input_dim()));
  mean.resize(points.rows());
  variance.resize(points.rows());
  Prediction p;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    predict(points.row(i).transpose(), p);
    mean(i) = p.mean;
    variance(i) = p.variance;
  }
}

Hyperparameters FittedGp::hyperparameters() const { return Hyperparameters::unpack(parameters(), input_dim()); }

Vector MarginalLikelihoodObjective::restart_parameters(const VectorCRef& initial, std::mt19937_64& rng) const {
  const ParameterBounds b = bounds();
  Vector theta = initial;
  std::uniform_real_distribution<double> offset(-1.5, 1.5);
  for (int i = 0; i < Hyperparameters::count(input_dim()); ++i)
    theta(i) = std::clamp(initial(i) + offset(rng), b.lower(i), b.upper(i));
  return theta;
}

TrainingSet GpBackend::select_training_points(const TrainingSet& data, std::uint64_t) const { return data; }

FitResult GpBackend::fit(const TrainingSet& data, const FitOptions& options) const {
  const auto start = std::chrono::steady_clock::now();
  options.validate();
  validate_training_set(data, std::string("GpBackend(") + std::string(name()) + ")::fit");
  TrainingSet selected = select_training_points(data, options.seed);
  validate_training_set(selected, std::string("GpBackend(") + std::string(name()) + ")::fit, selected points");
  auto objective_function = objective(selected, options);
  ParameterFit fitted = fit_parameters(*objective_function, options);
  objective_function.reset();
  FitResult result;
  result.summary = fitted.summary;
  result.summary.backend = std::string(name());
  result.summary.training_points = selected.size();
  result.model = condition(std::move(selected), fitted.parameters, options.jitter);
  result.summary.conditioning = result.model->conditioning();
  result.summary.nlml = result.summary.conditioning.negative_log_marginal_likelihood;
  result.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace gpilqg::gp
