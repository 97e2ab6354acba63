/// Running `gpilqg profile`: every backend at every size, the exact GP under the reference
/// hyperparameters as the baseline; a row over its memory or time budget skipped before any numeric
/// work (profile_budget.cpp), a fit past the time budget stopped with its best point (profile.hpp).

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>

#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/metrics.hpp"

#include "elapsed_seconds.hpp"

namespace gpilqg {

namespace {

using Clock = std::chrono::steady_clock;

/// The first `count` of one fixed permutation of [0, size) (seeded), in permutation order.
std::vector<int> nested_subset(int size, int count, std::uint64_t seed) {
  std::vector<int> order(static_cast<std::size_t>(size));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(static_cast<std::size_t>(std::min(count, size)));
  return order;
}

/// A backend's refusal of the data (std::invalid_argument, e.g. constant targets) as bad input naming
/// the file, the backend and the training set size: "<file>: backend 'exact', N = 60: <reason>".
InputError data_error(const std::filesystem::path& file, const ProfileRow& row, const std::invalid_argument& e) {
  return InputError(fmt::format("{}: backend '{}', N = {}: {}", file.string(), row.backend, row.size, e.what()));
}

/// Predicts the test set and scores it into `row`.
void score(const gp::FittedGp& model, const Matrix& test_inputs, const Vector& test_targets,
           const Vector& training_targets, ProfileRow& row) {
  const auto start = Clock::now();
  Vector mean, variance;
  model.predict(test_inputs, mean, variance);
  row.predict_seconds = seconds_since(start);
  const Vector predictive = (variance.array() + model.noise_variance()).matrix();
  const gp::RegressionScores s = gp::regression_scores(test_targets, mean, predictive, training_targets);
  row.smse = s.smse;
  row.mnlp = s.mnlp;
  row.msll = s.msll;
  row.nlml = model.negative_log_marginal_likelihood();
  row.conditioning = std::string(gp::to_string(model.conditioning().status));
  row.parameters = model.parameters().head(gp::Hyperparameters::count(model.input_dim()));
  row.status = "ok";
}

}  // namespace

void ProfileOptions::validate(const ProfileData& data) const {
  if (backends.empty()) throw InputError("--backends: expected at least one backend");
  if (sizes.empty()) throw InputError("--sizes: expected at least one size");
  for (int size : sizes)
    if (size < 0 || size > data.train.size())
      throw InputError(fmt::format("--sizes: {} is outside [1, {}] (the training set of {}; 'all' for all)", size,
                                   data.train.size(), data.name));
  if (!(memory_budget_bytes > 0.0)) throw InputError("--memory-budget-gb: expected a positive number");
  if (!(time_budget_seconds >= 0.0) || !std::isfinite(time_budget_seconds))
    throw InputError(fmt::format("--time-budget: is {}; expected a finite number of seconds >= 0 (0: no time budget)",
                                 time_budget_seconds));
  if (!(flops_per_second >= 0.0) || !std::isfinite(flops_per_second))
    throw InputError(fmt::format("flops_per_second: is {}; expected a finite number >= 0 (0: measured)", flops_per_second));
  if (max_test_points && *max_test_points < 1) throw InputError("--max-test: expected >= 1");
  if (start_from_reference && !data.reference)
    throw InputError("--start reference: " + data.name + " has no /reference_hyperparameters");
  try {
    settings.validate();
    fit.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
}

namespace {

/// The test set the rows are scored on: all of it, or the first max_test_points of a fixed permutation.
void test_set(const ProfileData& data, const ProfileOptions& options, Matrix& inputs, Vector& targets) {
  inputs = data.test_inputs;
  targets = data.test_targets;
  if (!options.max_test_points || *options.max_test_points >= data.test_inputs.rows()) return;
  const auto rows = nested_subset(static_cast<int>(data.test_inputs.rows()), *options.max_test_points, options.fit.seed + 1);
  inputs.resize(static_cast<Eigen::Index>(rows.size()), data.test_inputs.cols());
  targets.resize(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    inputs.row(static_cast<Eigen::Index>(r)) = data.test_inputs.row(rows[r]);
    targets(static_cast<Eigen::Index>(r)) = data.test_targets(rows[r]);
  }
}

}  // namespace

std::vector<ProfileCase> profile_cases(const ProfileData& data, const ProfileOptions& options) {
  std::vector<ProfileCase> cases;
  for (int requested : options.sizes) {
    const int size = requested == 0 ? data.train.size() : requested;
    if (data.reference) cases.push_back({"exact_reference", size});
    for (const std::string& name : options.backends) cases.push_back({name, size});
  }
  return cases;
}

ProfileReport profile_report_header(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options) {
  options.validate(data);
  ProfileReport report;
  report.file = file.string();
  report.data.name = data.name;
  report.data.format = data.format;
  report.data.target = data.target;
  report.data.train.inputs.resize(0, data.train.input_dim());
  report.options = options;
  Matrix test_inputs;
  Vector test_targets;
  test_set(data, options, test_inputs, test_targets);
  report.test_points = static_cast<int>(test_inputs.rows());
  return report;
}

namespace {

/// The FitOptions of a fitted row: the profile's, with the time budget as the fit's limit and, with
/// --start reference, the full warm start (the reference hyperparameters and the backend's extras).
/// For exact_reference: the reference hyperparameters, not optimised.
gp::FitOptions row_fit_options(const ProfileCase& c, const gp::GpBackend* backend, const gp::TrainingSet& subset,
                               const ProfileData& data, const ProfileOptions& options) {
  gp::FitOptions fit = options.fit;
  fit.max_seconds = options.time_budget_seconds;
  if (c.backend == "exact_reference") {
    fit.optimise = false;
    fit.warm_start = data.reference->pack();
  } else if (options.start_from_reference) {
    fit.warm_start = backend->objective(subset, fit)->initial_parameters();
    fit.warm_start.head(gp::Hyperparameters::count(subset.input_dim())) = data.reference->pack();
  }
  return fit;
}

/// Fits (or, for exact_reference, conditions) and scores into `row`.
void fit_and_score(const ProfileCase& c, const gp::GpBackend* backend, const gp::TrainingSet& subset,
                   const gp::FitOptions& fit_options, const ProfileOptions& options, const Matrix& test_inputs,
                   const Vector& test_targets, ProfileRow& row) {
  if (c.backend == "exact_reference") {
    const gp::ExactGpBackend exact(gp::ExactGpOptions{gp::ExactGpOptions::kAllPoints, options.settings.threads});
    const auto start = Clock::now();
    const auto model = exact.condition(subset, fit_options.warm_start, options.fit.jitter);
    row.fit_seconds = seconds_since(start);
    score(*model, test_inputs, test_targets, subset.targets, row);
    return;
  }
  const gp::FitResult fit = backend->fit(subset, fit_options);
  row.fit_seconds = fit.summary.seconds;
  row.evaluations = fit.summary.evaluations;
  row.termination = std::string(gp::to_string(fit.summary.termination));
  score(*fit.model, test_inputs, test_targets, subset.targets, row);
  if (fit.summary.termination == gp::FitTermination::TimeLimit)
    row.reason = fmt::format("stopped at time budget after {} evaluations", fit.summary.evaluations);
}

}  // namespace

ProfileRow run_profile_case(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options,
                            const ProfileCase& c) {
  Matrix test_inputs;
  Vector test_targets;
  test_set(data, options, test_inputs, test_targets);
  const auto order = nested_subset(data.train.size(), data.train.size(), options.fit.seed);
  const std::vector<int> rows(order.begin(), order.begin() + c.size);
  const gp::TrainingSet subset = data.train.subset(rows);
  ProfileRow row;
  row.backend = c.backend;
  row.size = c.size;
  if (c.backend == "exact_reference") row.termination = "not optimised";
  try {
    std::unique_ptr<gp::GpBackend> backend;
    if (c.backend != "exact_reference") {
      gp::BackendSettings settings = options.settings;
      settings.exact_points = c.size;
      backend = gp::make_backend(c.backend, settings);
    }
    const gp::FitOptions fit_options = row_fit_options(c, backend.get(), subset, data, options);
    row.reason = profile_skip_reason(c, subset, static_cast<int>(test_inputs.rows()), options, fit_options);
    if (!row.reason.empty()) {
      row.status = "skipped";
      return row;
    }
    fit_and_score(c, backend.get(), subset, fit_options, options, test_inputs, test_targets, row);
  } catch (const std::runtime_error& e) {  // e.g. conditioning failed even with jitter
    row.status = "failed";
    row.reason = e.what();
  } catch (const std::invalid_argument& e) {  // e.g. constant targets
    throw data_error(file, row, e);
  }
  return row;
}

ProfileReport run_profile(const std::filesystem::path& file, const ProfileData& data, const ProfileOptions& options,
                          const std::function<void(const ProfileRow&)>& progress) {
  ProfileReport report = profile_report_header(file, data, options);
  for (const ProfileCase& c : profile_cases(data, options)) {
    ProfileRow row = run_profile_case(file, data, options, c);
    if (progress) progress(row);
    report.rows.push_back(std::move(row));
  }
  return report;
}

}  // namespace gpilqg
