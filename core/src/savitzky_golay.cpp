#include "gpilqg/core/savitzky_golay.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/QR>

namespace gpilqg {

SavitzkyGolayDerivative::SavitzkyGolayDerivative(int window, int order, int derivative)
    : window_(window), order_(order), derivative_(derivative) {
  if (window < 3 || window % 2 == 0)
    throw std::invalid_argument("Savitzky-Golay window " + std::to_string(window) + "; expected an odd number >= 3");
  if (derivative < 1 || derivative > 2)
    throw std::invalid_argument("Savitzky-Golay derivative " + std::to_string(derivative) + "; expected 1 or 2");
  if (order < derivative || order >= window)
    throw std::invalid_argument("Savitzky-Golay order " + std::to_string(order) + "; expected " +
                                std::to_string(derivative) + " <= order < window (" + std::to_string(window) + ")");
  // One least-squares fit in the centred, scaled variable s_j = (j - h) / h (a well-conditioned design
  // B_{jk} = s_j^k), whose pseudo-inverse B^+ serves every position e: (j - e)^k = (h s_j + h - e)^k =
  // sum_l C(k, l) h^l (h - e)^(k - l) s_j^l, so A_e = B T_e with T_e upper triangular, A_e^+ = T_e^-1 B^+,
  // and the weights at e are d! times row d of that: d! (B^+)' v with T_e' v = e_d.
  const int h = window / 2, p = order + 1;
  Matrix B(window, p);
  for (int j = 0; j < window; ++j) {
    const double s = static_cast<double>(j - h) / h;
    double power = 1.0;
    for (int k = 0; k < p; ++k, power *= s) B(j, k) = power;
  }
  const Matrix pinv = B.colPivHouseholderQr().solve(Matrix::Identity(window, window));  // p x w
  Matrix T = Matrix::Zero(p, p);
  const Vector unit = Vector::Unit(p, derivative) * (derivative == 2 ? 2.0 : 1.0);
  weights_.reserve(static_cast<std::size_t>(window));
  for (int e = 0; e < window; ++e) {
    const double shift = static_cast<double>(h - e);
    for (int k = 0; k < p; ++k) {
      double binomial = 1.0;  // C(k, l)
      for (int l = 0; l <= k; ++l) {
        T(l, k) = binomial * std::pow(static_cast<double>(h), l) * std::pow(shift, k - l);
        binomial = binomial * static_cast<double>(k - l) / static_cast<double>(l + 1);
      }
    }
    const Vector v = T.transpose().triangularView<Eigen::Lower>().solve(unit);
    weights_.push_back(pinv.transpose() * v);
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
    dy(i) = weights(position).dot(y.segment(start, window_)) / step_power(dt);
  }
  return dy;
}

double SavitzkyGolayDerivative::step_power(double dt) const { return derivative_ == 2 ? dt * dt : dt; }

double SavitzkyGolayDerivative::noise_gain(double dt) const { return weights(window_ / 2).norm() / step_power(dt); }

double SavitzkyGolayDerivative::end_noise_gain(double dt) const {
  return std::max(weights(0).norm(), weights(window_ - 1).norm()) / step_power(dt);
}

}  // namespace gpilqg
