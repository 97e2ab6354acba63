// The Savitzky-Golay differentiator against closed-form derivatives: exact for polynomials of degree
// <= order at every position (centred and at the ends), close for a sine, zero lag, and a white-noise
// gain sqrt(sum c^2) / dt that Monte Carlo reproduces.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <utility>

#include <Eigen/QR>

#include "gpilqg/core/savitzky_golay.hpp"

namespace gpilqg {
namespace {

Vector sample(int count, double dt, const std::function<double(double)>& f) {
  Vector y(count);
  for (int i = 0; i < count; ++i) y(i) = f(i * dt);
  return y;
}

TEST(SavitzkyGolay, ExactForPolynomialsUpToItsOrder) {
  const double dt = 0.02;
  for (const auto& [window, order] : std::vector<std::pair<int, int>>{{5, 2}, {7, 2}, {7, 3}, {9, 4}, {3, 1}}) {
    const SavitzkyGolayDerivative sg(window, order);
    // p(t) = sum_k a_k (t - 0.3)^k with degree `order`, so p' is known in closed form.
    const auto p = [&](double t) {
      double v = 0.0;
      for (int k = 0; k <= order; ++k) v += (k + 1.5) * std::pow(t - 0.3, k);
      return v;
    };
    const auto dp = [&](double t) {
      double v = 0.0;
      for (int k = 1; k <= order; ++k) v += k * (k + 1.5) * std::pow(t - 0.3, k - 1);
      return v;
    };
    const Vector dy = sg.differentiate(sample(40, dt, p), dt);
    for (int i = 0; i < 40; ++i) EXPECT_NEAR(dy(i), dp(i * dt), 1e-8) << "window " << window << " order " << order << " i " << i;
  }
}

TEST(SavitzkyGolay, CubicThroughAQuadraticFitHasItsClosedFormError) {
  // Centred, order 2 (= the least-squares slope): for y = t^3 the estimate is 3 t^2 + dt^2 sum i^4 / sum i^2
  // = 3 t^2 + 7 dt^2 for window 7. A test that the filter is not exact beyond its order, and by how much.
  const double dt = 0.1;
  const SavitzkyGolayDerivative sg(7, 2);
  const Vector dy = sg.differentiate(sample(20, dt, [](double t) { return t * t * t; }), dt);
  for (int i = 3; i < 17; ++i) EXPECT_NEAR(dy(i), 3.0 * (i * dt) * (i * dt) + 7.0 * dt * dt, 1e-9) << i;
}

TEST(SavitzkyGolay, SineIsScaledWithoutLag) {
  // The centred weights are antisymmetric, so for y = sin(w t) the estimate is exactly
  // w cos(w t) * R with R = sum_i c_i sin(w i dt) / (w dt): no phase shift (zero lag) at any frequency,
  // and R -> 1 as w dt -> 0.
  const double dt = 0.01, w = 2.0 * M_PI * 1.5;
  const SavitzkyGolayDerivative sg(7, 2);
  const Vector& c = sg.weights(3);
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(c(i), -c(6 - i), 1e-12);
  double R = 0.0;
  for (int i = -3; i <= 3; ++i) R += c(i + 3) * std::sin(w * i * dt);
  R /= w * dt;
  EXPECT_NEAR(R, 1.0, 0.02);
  const Vector dy = sg.differentiate(sample(300, dt, [&](double t) { return std::sin(w * t); }), dt);
  for (int i = 3; i < 297; ++i) EXPECT_NEAR(dy(i), R * w * std::cos(w * i * dt), 1e-9) << i;
  // The ends use the off-centre fits: not exact for a sine, but close at this w dt.
  EXPECT_NEAR(dy(0), w, 0.05 * w);
  EXPECT_EQ(SavitzkyGolayDerivative::lag(), 0.0);
}

TEST(SavitzkyGolay, NoiseGainMatchesClosedFormAndMonteCarlo) {
  const double dt = 0.02;
  const SavitzkyGolayDerivative sg(7, 2);
  // Window 7, order 2: c_i = i / 28 for i = -3..3, so sum c^2 = 1/28.
  EXPECT_NEAR(sg.noise_gain(dt), std::sqrt(1.0 / 28.0) / dt, 1e-10);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 200000;
  Vector noise(n);
  for (int i = 0; i < n; ++i) noise(i) = normal(rng);
  const Vector d = sg.differentiate(noise, dt);
  const Vector interior = d.segment(3, n - 6);
  const double measured = std::sqrt(interior.squaredNorm() / static_cast<double>(interior.size()));
  RecordProperty("noise_gain_formula", std::to_string(sg.noise_gain(dt)));
  RecordProperty("noise_gain_measured", std::to_string(measured));
  EXPECT_NEAR(measured / sg.noise_gain(dt), 1.0, 0.01) << measured << " vs " << sg.noise_gain(dt);
  // The ends are off-centre and noisier.
  EXPECT_GT(sg.end_noise_gain(dt), sg.noise_gain(dt));
}

// The weights of every position from the one centred factorisation are those of a least-squares fit
// solved at that position itself (row 1 of the pseudo-inverse of A_jk = (j - e)^k), to rounding.
TEST(SavitzkyGolay, WeightsAreTheFitSolvedAtEveryPosition) {
  for (const auto& [window, order] : {std::pair{3, 1}, std::pair{7, 2}, std::pair{21, 4}, std::pair{61, 2}, std::pair{61, 4}}) {
    const SavitzkyGolayDerivative filter(window, order);
    for (int e = 0; e < window; ++e) {
      Matrix A(window, order + 1);
      for (int j = 0; j < window; ++j)
        for (int k = 0; k <= order; ++k) A(j, k) = std::pow(static_cast<double>(j - e), k);
      const Vector solved = A.colPivHouseholderQr().solve(Matrix::Identity(window, window)).row(1).transpose();
      EXPECT_LE((filter.weights(e) - solved).norm(), 1e-9 * solved.norm()) << "window " << window << ", order "
                                                                             << order << ", position " << e;
    }
  }
}

// The second derivative (derivative 2) against closed forms: exact for polynomials of degree <= order
// at every position; centred weights symmetric; the centred order-2 fit over 3 samples is the
// central difference (1, -2, 1); and its weights are 2 times row 2 of the fit solved at each position.
TEST(SavitzkyGolay, SecondDerivativeIsExactForPolynomialsAndIsTheFitsSecondCoefficient) {
  const double dt = 0.01;
  for (const auto& [window, order] : std::vector<std::pair<int, int>>{{3, 2}, {7, 2}, {9, 3}, {21, 4}}) {
    const SavitzkyGolayDerivative sg(window, order, 2);
    EXPECT_EQ(sg.derivative(), 2);
    const auto p = [&](double t) {
      double v = 0.0;
      for (int k = 0; k <= order; ++k) v += (k + 1.5) * std::pow(t - 0.2, k);
      return v;
    };
    const auto ddp = [&](double t) {
      double v = 0.0;
      for (int k = 2; k <= order; ++k) v += k * (k - 1) * (k + 1.5) * std::pow(t - 0.2, k - 2);
      return v;
    };
    const Vector d2y = sg.differentiate(sample(50, dt, p), dt);
    for (int i = 0; i < 50; ++i)
      EXPECT_NEAR(d2y(i), ddp(i * dt), 1e-6 * (1.0 + std::abs(ddp(i * dt)))) << "window " << window << " i " << i;
    const Vector& c = sg.weights(window / 2);
    for (int i = 0; i < window; ++i) EXPECT_NEAR(c(i), c(window - 1 - i), 1e-12);
    for (int e = 0; e < window; ++e) {
      Matrix A(window, order + 1);
      for (int j = 0; j < window; ++j)
        for (int k = 0; k <= order; ++k) A(j, k) = std::pow(static_cast<double>(j - e), k);
      const Vector solved = 2.0 * A.colPivHouseholderQr().solve(Matrix::Identity(window, window)).row(2).transpose();
      EXPECT_LE((sg.weights(e) - solved).norm(), 1e-9 * solved.norm()) << "window " << window << ", position " << e;
    }
  }
  const SavitzkyGolayDerivative three(3, 2, 2);
  const Vector& central = three.weights(1);
  EXPECT_NEAR(central(0), 1.0, 1e-12);
  EXPECT_NEAR(central(1), -2.0, 1e-12);
  EXPECT_NEAR(central(2), 1.0, 1e-12);
  // Centred, order 2 is exact to degree 3 (symmetric weights): t^3 gives 6 t exactly.
  const SavitzkyGolayDerivative sg(7, 2, 2);
  const Vector d2y = sg.differentiate(sample(20, dt, [](double t) { return t * t * t; }), dt);
  for (int i = 3; i < 17; ++i) EXPECT_NEAR(d2y(i), 6.0 * i * dt, 1e-7) << i;
  EXPECT_NEAR(sg.noise_gain(dt), sg.weights(3).norm() / (dt * dt), 1e-6);
  EXPECT_THROW(SavitzkyGolayDerivative(5, 1, 2), std::invalid_argument);  // a line has no curvature
  EXPECT_THROW(SavitzkyGolayDerivative(5, 2, 3), std::invalid_argument);
}

TEST(SavitzkyGolay, RejectsBadSettingsAndShortSignals) {
  EXPECT_THROW(SavitzkyGolayDerivative(6, 2), std::invalid_argument);
  EXPECT_THROW(SavitzkyGolayDerivative(1, 0), std::invalid_argument);
  EXPECT_THROW(SavitzkyGolayDerivative(5, 5), std::invalid_argument);
  const SavitzkyGolayDerivative sg(5, 2);
  EXPECT_THROW(sg.differentiate(Vector::Zero(4), 0.1), std::invalid_argument);
  EXPECT_THROW(sg.differentiate(Vector::Zero(10), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
