#include "gpilqg/experiments/normalised_cost.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

namespace {
double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (const double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}
}  // namespace

NormalisedCost normalised_cost(const std::vector<double>& costs, const std::vector<double>& reference_costs) {
  if (costs.empty() || costs.size() != reference_costs.size())
    throw std::invalid_argument("normalised_cost: " + std::to_string(costs.size()) + " costs and " +
                                std::to_string(reference_costs.size()) +
                                " reference costs; expected the same number, at least one");
  const double b = mean(reference_costs);
  if (!(b > 0.0) || !std::isfinite(b))
    throw std::invalid_argument("normalised_cost: the reference's mean cost is " + std::to_string(b) +
                                "; expected positive and finite");
  NormalisedCost out;
  out.value = mean(costs) / b;
  const auto E = static_cast<double>(costs.size());
  if (costs.size() < 2) return out;
  double sum = 0.0;
  for (std::size_t i = 0; i < costs.size(); ++i) {
    const double d = costs[i] - out.value * reference_costs[i];
    sum += d * d;
  }
  const double se = std::sqrt(sum / (E * (E - 1.0))) / b;
  if (std::isfinite(se)) out.standard_error = se;
  return out;
}

}  // namespace gpilqg
