/// The regression scores (metrics.hpp) on hand-computed cases.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gpilqg/gp/metrics.hpp"

namespace gpilqg::gp {
namespace {

TEST(Metrics, HandComputedValues) {
  Vector y(4), mu(4), s2(4), train(3);
  y << 1, 2, 3, 4;            // var = 1.25
  mu << 1, 2, 3, 5;           // squared errors 0 0 0 1
  s2 << 0.5, 0.5, 0.5, 2.0;
  train << 0, 1, 2;           // mean 1, var 2/3
  EXPECT_NEAR(standardised_mean_squared_error(y, mu), 0.25 / 1.25, 1e-15);
  const double two_pi = 2.0 * std::numbers::pi;
  const double mnlp = (3 * 0.5 * std::log(two_pi * 0.5) + 0.5 * std::log(two_pi * 2.0) + 1.0 / 4.0) / 4.0;
  EXPECT_NEAR(mean_negative_log_probability(y, mu, s2), mnlp, 1e-15);
  double trivial = 0.0;
  for (int i = 0; i < 4; ++i) trivial += 0.5 * std::log(two_pi * 2.0 / 3.0) + std::pow(y(i) - 1.0, 2) / (2.0 * 2.0 / 3.0);
  EXPECT_NEAR(mean_standardised_log_loss(y, mu, s2, train), mnlp - trivial / 4.0, 1e-14);
  const RegressionScores s = regression_scores(y, mu, s2, train);
  EXPECT_EQ(s.smse, standardised_mean_squared_error(y, mu));
  EXPECT_EQ(s.msll, mean_standardised_log_loss(y, mu, s2, train));
}

TEST(Metrics, BadInputIsRejected) {
  Vector y(2), mu(3), s2(2);
  y << 1, 2;
  mu << 1, 2, 3;
  s2 << 1, 0;
  EXPECT_THROW((void)standardised_mean_squared_error(y, mu), std::invalid_argument);
  EXPECT_THROW((void)mean_negative_log_probability(y, y, s2), std::invalid_argument);
  EXPECT_THROW((void)standardised_mean_squared_error(Vector::Ones(3), Vector::Ones(3)), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg::gp
