#include "gpilqg/core/noise.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gpilqg {

void DiffusionColumns::resize(int n, int m, int p) {
  columns.setZero(n, p);
  d_dx.resize(static_cast<std::size_t>(p));
  d_du.resize(static_cast<std::size_t>(p));
  for (auto& d : d_dx) d.setZero(n, n);
  for (auto& d : d_du) d.setZero(n, m);
}

namespace {

int nonzero_count(const Vector& v) { return static_cast<int>((v.array() != 0.0).count()); }

void validate_std(const Vector& v, int expected, const char* field) {
  if (v.size() != 0 && v.size() != expected)
    throw std::invalid_argument(std::string("noise field '") + field + "' has " +
                                std::to_string(v.size()) + " entries; expected " +
                                std::to_string(expected) + " (or none)");
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i)) || v(i) < 0.0)
      throw std::invalid_argument(std::string("noise field '") + field + "' entry " +
                                  std::to_string(i) + " is " + std::to_string(v(i)) +
                                  "; expected a finite standard deviation >= 0");
}

}  // namespace

int ActuatorNoise::column_count() const {
  return nonzero_count(additive_std) + nonzero_count(multiplicative_std) + nonzero_count(state_std);
}

void ActuatorNoise::validate(int n, int m) const {
  validate_std(additive_std, m, "additive_std");
  validate_std(multiplicative_std, m, "multiplicative_std");
  validate_std(state_std, n, "state_std");
}

}  // namespace gpilqg
