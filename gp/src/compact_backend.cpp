#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "compact_internal.hpp"

namespace gpilqg::gp {

void CompactOptions::validate() const {
  if (initial_neighbours < 1)
    throw std::invalid_argument("CompactOptions::initial_neighbours = " + std::to_string(initial_neighbours) +
                                "; expected >= 1");
  if (max_neighbours < initial_neighbours)
    throw std::invalid_argument("CompactOptions::max_neighbours = " + std::to_string(max_neighbours) +
                                "; expected >= initial_neighbours = " + std::to_string(initial_neighbours));
  if (max_factor_nonzeros < 1)
    throw std::invalid_argument("CompactOptions::max_factor_nonzeros = " + std::to_string(max_factor_nonzeros) +
                                "; expected >= 1");
  if (threads < 1) throw std::invalid_argument("CompactOptions::threads = " + std::to_string(threads) + "; expected >= 1");
}

CompactBackend::CompactBackend(CompactOptions options) : options_(options) { options_.validate(); }

std::unique_ptr<MarginalLikelihoodObjective> CompactBackend::objective(const TrainingSet& data,
                                                                       const FitOptions& options) const {
  validate_training_set(data, "CompactBackend::objective");
  refuse_known_noise(data, name());
  options.validate();
  return detail::make_compact_objective(data, options, options_);
}

std::unique_ptr<FittedGp> CompactBackend::condition(TrainingSet data, const VectorCRef& parameters,
                                                    const JitterSchedule& jitter) const {
  refuse_known_noise(data, name());
  validate_training_set(data, "CompactBackend::condition");
  jitter.validate();
  return detail::make_compact_fitted_gp(std::move(data), parameters, jitter, options_);
}

namespace detail {

void check_compact_parameters(const VectorCRef& parameters, int input_dim, const char* who) {
  if (parameters.size() != Hyperparameters::count(input_dim))
    throw std::invalid_argument(std::string(who) + ": parameter vector has " + std::to_string(parameters.size()) +
                                " entries; expected D + 2 = " + std::to_string(Hyperparameters::count(input_dim)) +
                                " ([log l; log sf; log sn]) for D = " + std::to_string(input_dim));
  (void)Hyperparameters::unpack(parameters, input_dim);  // throws for non-finite entries
}

void build_compact_system(const Matrix& inputs, const WendlandKernel& kernel, const NeighbourGrid& grid,
                          double noise_variance, const JitterSchedule& jitter, const CompactOptions& options,
                          CholmodFactorizer& factorizer, CompactSystem& system) {
  system.outcome = SparseFactorOutcome{};
  if (!grid.lower_pattern(options.max_factor_nonzeros, options.threads, system.pattern)) {
    system.outcome.over_budget = true;
    system.outcome.factor_nonzeros = static_cast<double>(options.max_factor_nonzeros) + 1.0;
    return;
  }
  const LowerPattern& p = system.pattern;
  system.values.resize(p.row.size());
  Vector xj(inputs.cols());
  for (int j = 0; j < p.size; ++j) {
    xj = inputs.row(j).transpose();
    const auto first = static_cast<std::size_t>(p.column_start[static_cast<std::size_t>(j)]);
    system.values[first] = kernel.signal_variance();
    for (auto q = first + 1; q < static_cast<std::size_t>(p.column_start[static_cast<std::size_t>(j) + 1]); ++q)
      system.values[q] = kernel.value(kernel.squared_distance(inputs, p.row[q], xj));
  }
  system.outcome = factorizer.factorize(p, system.values, noise_variance, kernel.signal_variance() + noise_variance,
                                        jitter, options.max_factor_nonzeros, system.factor);
}

double compact_nlml(const SupernodalFactor& factor, const Vector& targets, Vector& alpha) {
  factor.solve(targets, alpha);
  return 0.5 * targets.dot(alpha) + factor.half_log_determinant() +
         0.5 * static_cast<double>(targets.size()) * std::log(2.0 * std::numbers::pi);
}

}  // namespace detail
}  // namespace gpilqg::gp
