#include "gpilqg/core/savitzky_golay.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/QR>

namespace gpilqg {

SavitzkyGolayDerivative::SavitzkyGolayDerivative(int window, int order) : window_(window), order_(order) {
  if (window < 3 || window % 2 == 0)
    throw std::invalid_argument("Savitzky-Golay window " + std::to_string(window) + "; expected an odd number >= 3");
  if (order < 1 || order >= window)
    throw std::invalid_argument("Savitzky-Golay order " + std::to_string(order) + "; expected 1 <= order < window (" +
                                std::to_string(window) + ")");
  weights_.reserve(static_cast<std::size_t>(window));
  for (int e = 0; e < window; ++e) {
    // A_{jk} = (j - e)^k; the least-squares solution of A a = I gives the pseudo-inverse A^+,
    // whose row 1 maps the samples to the fitted slope at e.
    Matrix A(window, order + 1);
    for (int j = 0; j < window; ++j)
      for (int k = 0; k <= order; ++k) A(j, k) = std::pow(static_cast<double>(j - e), k);
    const Matrix pinv = A.colPivHouseholderQr().solve(Matrix::Identity(window, window));
    weights_.push_back(pinv.row(1).transpose());
  }
}

Vector SavitzkyGolayDerivative::differentiate(const VectorCRef& y, double dt) const {
  if (!(dt > 0.0)) throw std::invalid_argument("Savitzky-Golay derivative: dt must be positive");
  const Eigen::Index n = y.size();
  if (n < window_)
    throw std::invalid_argument("Savitzky-Golay derivative: " + std::to_string(n) + " samples; expected at least the window, " +
                                std::to_string(window_));
  const int h = window_ / 2;
  Vector dy(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    // The window starts at i - h in the interior, and stays on the first/last w samples at the ends.
    const Eigen::Index start = std::clamp<Eigen::Index>(i - h, 0, n - window_);
    const int position = static_cast<int>(i - start);
    dy(i) = weights(position).dot(y.segment(start, window_)) / dt;
  }
  return dy;
}

double SavitzkyGolayDerivative::noise_gain(double dt) const { return weights(window_ / 2).norm() / dt; }

double SavitzkyGolayDerivative::end_noise_gain(double dt) const {
  return std::max(weights(0).norm(), weights(window_ - 1).norm()) / dt;
}

}  // namespace gpilqg
