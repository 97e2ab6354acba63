/// The budgets of `gpilqg profile` (profile.hpp): a row's memory and predicted time, checked before any
/// numeric work; the time from a flop count of the row's algorithm at a measured machine rate.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/gp/compact.hpp"
#include "gpilqg/gp/flop_rate.hpp"

namespace gpilqg {

namespace {

/// Flops per second no machine that runs this is slower than: a row needing at most budget x this
/// cannot exceed the budget, and the rate is not measured for it.
constexpr double kSlowestRate = 1e9;

/// Two significant digits, exponent without sign or padding: "2.1e12", "3.1e5", "48".
std::string flops_text(double flops) {
  std::string text = fmt::format("{:.2g}", flops);  // "2.1e+12", "3.1e+05", "48"
  const auto e = text.find('e');
  if (e == std::string::npos) return text;
  std::string exponent = text.substr(e + 1);
  const bool negative = exponent.front() == '-';
  exponent.erase(0, exponent.find_first_not_of("+-0"));
  return text.substr(0, e + 1) + (negative ? "-" : "") + (exponent.empty() ? "0" : exponent);
}

/// Whole seconds with thousands separators ("1,400"), or three digits below 10 s ("2.45", "0.001").
std::string seconds_text(double seconds) {
  if (seconds < 10.0) return fmt::format("{:.3g}", seconds);
  std::string digits = fmt::format("{:.0f}", seconds);
  for (auto at = static_cast<std::ptrdiff_t>(digits.size()) - 3; at > 0; at -= 3)
    digits.insert(static_cast<std::size_t>(at), ",");
  return digits;
}

/// The point the fit evaluates first: the warm start clipped to the bounds (as fit_parameters does),
/// else the data-driven start.
Vector first_start(const gp::GpBackend& backend, const gp::TrainingSet& subset, const gp::FitOptions& fit) {
  const auto objective = backend.objective(subset, fit);
  Vector start = objective->initial_parameters();
  if (fit.warm_start.size() == start.size()) {
    const gp::ParameterBounds bounds = objective->bounds();
    start = fit.warm_start.cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  }
  return start;
}

/// One evaluation and the final stage of the compact backend, from CHOLMOD's symbolic analysis.
void compact_work(const gp::TrainingSet& subset, int test_points, const ProfileOptions& options,
                  const gp::FitOptions& fit, ProfileRowWork& work) {
  const auto backend = gp::make_backend("compact", options.settings);
  const auto& compact = dynamic_cast<const gp::CompactBackend&>(*backend);
  const int d = subset.input_dim();
  const Vector start = first_start(compact, subset, fit);
  const gp::CompactFactorAnalysis a = compact.analyze(subset, start.head(gp::Hyperparameters::count(d)));
  if (a.over_budget) {  // evaluations there fail before any numerical work
    work.what = "CHOLMOD: the factor at the start exceeds max_factor_nonzeros, evaluations fail at once";
    return;
  }
  const double t = test_points;
  work.per_evaluation = a.factorisation_flops + a.inverse_subset_flops + static_cast<double>(a.kernel_nonzeros) * (6.0 * d + 40.0);
  work.final = a.factorisation_flops + 2.0 * t * a.factor_nonzeros;
  work.what = fmt::format("CHOLMOD: {} flops per factorisation + {} for the gradient's inverse subset,",
                          flops_text(a.factorisation_flops), flops_text(a.inverse_subset_flops));
}

}  // namespace

double exact_memory_bytes(std::int64_t n, bool fitted) {
  return (fitted ? 16.0 : 8.0) * static_cast<double>(n) * static_cast<double>(n);
}

std::optional<RowMemory> profile_row_memory(const ProfileCase& c, const ProfileOptions& options) {
  const double n = static_cast<double>(c.size);
  const double workers = std::max(1, options.settings.threads);
  if (c.backend == "exact" || c.backend == "exact_reference") {
    const bool fitted = c.backend == "exact";
    return RowMemory{exact_memory_bytes(c.size, fitted),
                     fmt::format("the dense exact GP at N = {} ({} N x N matrices)", c.size, fitted ? 2 : 1)};
  }
  if (c.backend == "fitc") {
    const double m = std::min<double>(options.settings.inducing, n);
    return RowMemory{8.0 * (4.0 * n * m + (6.0 + 2.0 * workers) * m * m),
                     fmt::format("FITC at N = {} with M = {} inducing points (4 M x N and {} M x M matrices)", c.size,
                                 static_cast<long>(m), 6 + 2 * static_cast<long>(workers))};
  }
  if (c.backend == "ssgp") {
    const double m = 2.0 * options.settings.frequencies;
    return RowMemory{8.0 * (2.0 * n * m + (4.0 + workers) * m * m),
                     fmt::format("SSGP at N = {} with {} frequencies (2 N x 2M and {} 2M x 2M matrices)", c.size,
                                 options.settings.frequencies, 4 + static_cast<long>(workers))};
  }
  return std::nullopt;
}

ProfileRowWork profile_row_work(const ProfileCase& c, const gp::TrainingSet& subset, int test_points,
                                const ProfileOptions& options, const gp::FitOptions& fit) {
  const double n = c.size, d = subset.input_dim(), t = test_points;
  const int starts = 1 + fit.restarts + (fit.warm_start.size() != 0 ? 1 : 0);
  ProfileRowWork work;
  work.evaluations = fit.optimise ? 1 + fit.max_evaluations * starts : 1;
  if (c.backend == "exact" || c.backend == "exact_reference") {
    work.per_evaluation = n * n * n + n * n * (3.0 * d + 20.0);
    work.final = 2.0 * n * n * n / 3.0 + t * n * n + t * n * (3.0 * d + 20.0);
    work.what = fmt::format("dense: {} flops per evaluation", flops_text(work.per_evaluation));
    if (c.backend == "exact_reference") {
      work.evaluations = 0;
      work.what = "dense";
    }
  } else if (c.backend == "fitc" || c.backend == "ssgp") {
    const bool fitc = c.backend == "fitc";
    const double m = fitc ? std::min<double>(options.settings.inducing, n) : 2.0 * options.settings.frequencies;
    work.per_evaluation = (fitc ? 12.0 : 3.0) * n * m * m + 2.0 * n * m * (3.0 * d + 20.0) + 7.0 * m * m * m / 3.0;
    work.final = 4.0 * n * m * m + m * m * m / 3.0 + t * (m * m + m * (3.0 * d + 20.0));
    work.what = fmt::format("{}: {} flops per evaluation", fitc ? "FITC" : "SSGP", flops_text(work.per_evaluation));
  } else if (c.backend == "compact") {
    compact_work(subset, test_points, options, fit, work);
  }
  return work;
}

std::string profile_skip_reason(const ProfileCase& c, const gp::TrainingSet& subset, int test_points,
                                const ProfileOptions& options, const gp::FitOptions& fit) {
  if (const std::optional<RowMemory> memory = profile_row_memory(c, options);
      memory && memory->bytes > options.memory_budget_bytes) {
    const std::string& what = memory->what;
    const auto at = what.find(" (");  // "<model> needs X GiB (<matrices>)": the size before the matrices
    return fmt::format("{} needs {:.2f} GiB{}, over the budget of {:.2f} GiB", what.substr(0, at),
                       memory->bytes / (1ull << 30), what.substr(at), options.memory_budget_bytes / (1ull << 30));
  }
  const double budget = options.time_budget_seconds;
  if (!(budget > 0.0)) return {};
  const ProfileRowWork work = profile_row_work(c, subset, test_points, options, fit);
  const double flops = work.total();
  if (options.flops_per_second <= 0.0 && flops <= budget * kSlowestRate) return {};
  const double rate = options.flops_per_second > 0.0 ? options.flops_per_second : gp::dense_flop_rate(options.settings.threads);
  const double seconds = flops / rate;
  if (seconds <= budget) return {};
  const std::string count = work.evaluations > 0 ? fmt::format("{} x {} evaluations + {} to condition and predict", work.what,
                                                                work.evaluations, flops_text(work.final))
                                                  : fmt::format("{}: {} flops to condition and predict", work.what, flops_text(work.final));
  return fmt::format("predicted {} s > {} s time budget ({}, at {:.3g} GFLOP/s)", seconds_text(seconds),
                     seconds_text(budget), count, rate / 1e9);
}

}  // namespace gpilqg
