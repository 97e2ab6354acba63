#include "gpilqg/experiments/diagnosis/chi_square.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg::diagnosis {

double chi_square_survival(double x, int dof) {
  if (dof < 1) throw std::invalid_argument("chi-square: degrees of freedom " + std::to_string(dof) + "; expected >= 1");
  if (!(x > 0.0)) return 1.0;
  if (std::isinf(x)) return 0.0;
  const double y = 0.5 * x;
  const double log_y = std::log(y);
  double sum = 0.0;
  if (dof % 2 == 0) {
    for (int j = 0; j < dof / 2; ++j) sum += std::exp(j * log_y - y - std::lgamma(j + 1.0));
  } else {
    sum = std::erfc(std::sqrt(y));
    for (int j = 0; j <= (dof - 3) / 2; ++j) sum += std::exp((j + 0.5) * log_y - y - std::lgamma(j + 1.5));
  }
  return std::min(1.0, std::max(0.0, sum));
}

double chi_square_quantile(double p, int dof) {
  if (dof < 1) throw std::invalid_argument("chi-square: degrees of freedom " + std::to_string(dof) + "; expected >= 1");
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("chi-square: probability " + std::to_string(p) + "; expected a value in (0, 1)");
  const double tail = 1.0 - p;
  // An upper bracket: double until the tail beyond it is below the wanted one.
  double low = 0.0, high = dof + 10.0 * std::sqrt(2.0 * dof) + 10.0;
  while (chi_square_survival(high, dof) > tail) high *= 2.0;
  for (int i = 0; i < 200 && high - low > 1e-12 * high; ++i) {
    const double mid = 0.5 * (low + high);
    (chi_square_survival(mid, dof) > tail ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

}  // namespace gpilqg::diagnosis
