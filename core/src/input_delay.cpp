#include "gpilqg/core/input_delay.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace gpilqg {

Matrix delay_controls(const Matrix& u, double delay) {
  if (!std::isfinite(delay) || delay < 0.0 || delay > kMaxInputDelay)
    throw std::invalid_argument(fmt::format("input delay {} control periods; expected a value in [0, {}]", delay, kMaxInputDelay));
  if (delay == 0.0) return u;
  const auto whole = static_cast<Eigen::Index>(std::floor(delay));
  const double fraction = delay - static_cast<double>(whole);
  Matrix out(u.rows(), u.cols());
  for (Eigen::Index t = 0; t < u.rows(); ++t) {
    const Eigen::Index a = std::max<Eigen::Index>(0, t - whole), b = std::max<Eigen::Index>(0, t - whole - 1);
    out.row(t) = (1.0 - fraction) * u.row(a) + fraction * u.row(b);
  }
  return out;
}

}  // namespace gpilqg
