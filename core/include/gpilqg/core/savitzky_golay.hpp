#pragma once
/// @file savitzky_golay.hpp
/// The Savitzky-Golay smoothing differentiator: the first (or second) derivative of a uniformly sampled
/// signal from a least-squares polynomial fit over a sliding window.
///
/// Over a window of w = 2h + 1 samples y_0 .. y_{w-1} at step dt, fit p(s) = sum_{k=0..order} a_k (s - e)^k
/// (s in samples, e the evaluation position within the window) by least squares. With the design
/// matrix A_{jk} = (j - e)^k the fit is a = A^+ y, and the derivative at e is
///
///     y'(e dt) ~ a_1 / dt = (1 / dt) sum_j c_j y_j,   c = row 1 of A^+ = e_1' (A'A)^{-1} A'.
///
/// The second derivative is 2 a_2 / dt^2 = (1 / dt^2) sum_j c_j y_j with c = 2 e_2' A^+ (derivative 2;
/// order >= 2). Its centred weights are symmetric (c_{h+i} = c_{h-i}), so it is zero-phase too, and
/// for an even order exact to degree order + 1.
///
/// Properties (tests/core/savitzky_golay_test.cpp checks each):
/// - exact for every polynomial of degree <= order, at any evaluation position e;
/// - in the interior the window is centred (e = h): the weights are antisymmetric, c_{h+i} = -c_{h-i},
///   so the filter's phase is exactly -90 degrees at every frequency and its lag is zero;
/// - white noise of standard deviation sigma on y gives derivative noise sigma * G with the noise gain
///   G = sqrt(sum_j c_j^2) / dt (e.g. w = 7, order 2: sum c^2 = 1/28, G = 0.189 / dt);
/// - at the first and last h samples of a signal there is no centred window; the same fit over the
///   first (last) w samples is evaluated off-centre at e = 0 .. h-1 (e = h+1 .. w-1). That keeps
///   every sample and is still exact for polynomials of degree <= order, but it is noisier
///   (end_noise_gain) and, for higher-degree signals, less accurate than the centred fit.
///
/// Cost of the weights: one QR factorisation of the centred design (w x (order + 1), in (j - h) / h,
/// well conditioned at any w) for every position, each position's weights then a triangular solve of
/// order + 1 unknowns and one product: O(w^2 order) for the filter, against O(w^3 order) for a fit per position.

#include <vector>

#include "gpilqg/core/types.hpp"

namespace gpilqg {

class SavitzkyGolayDerivative {
 public:
  /// Throws std::invalid_argument unless `window` is odd and >= 3, `derivative` is 1 or 2 and
  /// `derivative` <= `order` < `window`.
  SavitzkyGolayDerivative(int window, int order, int derivative = 1);

  int window() const { return window_; }
  int order() const { return order_; }
  int derivative() const { return derivative_; }  ///< 1: dy/dt; 2: d^2y/dt^2

  /// The weights c_0 .. c_{w-1} of the derivative at position `position` (0 .. w-1) of the window,
  /// per unit step (divide the weighted sum by dt^derivative()). The centre is window() / 2.
  const Vector& weights(int position) const { return weights_.at(static_cast<std::size_t>(position)); }

  /// dy/dt (d^2y/dt^2 for derivative 2) at every sample of `y` (uniform step `dt` > 0): centred fits in the interior, the
  /// off-centre fits of the first and last windows at the ends. Throws std::invalid_argument when
  /// y has fewer than window() samples or dt is not positive.
  Vector differentiate(const VectorCRef& y, double dt) const;

  /// G = sqrt(sum_j c_j^2) / dt^derivative() of the centred window: the standard deviation of the derivative
  /// estimate per unit standard deviation of white noise on the samples.
  double noise_gain(double dt) const;
  /// The same for the worst off-centre position (the first or last sample of a signal).
  double end_noise_gain(double dt) const;
  /// The lag of the centred estimate [s]: zero (antisymmetric weights).
  static constexpr double lag() { return 0.0; }

 private:
  double step_power(double dt) const;  ///< dt^derivative()

  int window_;
  int order_;
  int derivative_;
  std::vector<Vector> weights_;  ///< one weight vector per evaluation position
};

}  // namespace gpilqg
