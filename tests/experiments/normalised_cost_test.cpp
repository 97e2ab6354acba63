/// The normalised cost's standard error (normalised_cost.hpp) against Monte Carlo: the spread of R over
/// many independent repetitions of E paired rollouts.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gpilqg/experiments/normalised_cost.hpp"

namespace gpilqg {
namespace {

/// E pairs (a_i, b_i): b_i = 10 (1 + 0.1 w_i), a_i = 1.1 b_i (1 + 0.02 v_i) + 0.3 v'_i, the two
/// costs correlated through the shared stream w_i as evaluation rollouts are.
void draw(std::mt19937_64& rng, int E, std::vector<double>& a, std::vector<double>& b) {
  std::normal_distribution<double> normal;
  a.assign(static_cast<std::size_t>(E), 0.0);
  b.assign(static_cast<std::size_t>(E), 0.0);
  for (int i = 0; i < E; ++i) {
    b[static_cast<std::size_t>(i)] = 10.0 * (1.0 + 0.1 * normal(rng));
    a[static_cast<std::size_t>(i)] = 1.1 * b[static_cast<std::size_t>(i)] * (1.0 + 0.02 * normal(rng)) + 0.3 * normal(rng);
  }
}

TEST(NormalisedCost, StandardErrorMatchesTheMonteCarloSpreadOfTheRatio) {
  std::mt19937_64 rng(5);
  constexpr int kRepetitions = 20000, E = 20;
  std::vector<double> a, b, ratios;
  double se_sum = 0.0;
  for (int r = 0; r < kRepetitions; ++r) {
    draw(rng, E, a, b);
    const NormalisedCost c = normalised_cost(a, b);
    ratios.push_back(c.value);
    se_sum += c.standard_error;
  }
  double mean = 0.0;
  for (const double x : ratios) mean += x / kRepetitions;
  double var = 0.0;
  for (const double x : ratios) var += (x - mean) * (x - mean) / (kRepetitions - 1);
  // The Monte Carlo std is known to about 0.5% (1 / sqrt(2 * 20000)); the delta method's bias at E = 20
  // and the average of the estimated se's (E[s] < s) are within a few percent.
  EXPECT_NEAR(se_sum / kRepetitions, std::sqrt(var), 0.05 * std::sqrt(var));
  EXPECT_NEAR(mean, 1.1, 0.002);
  // Pairing: the ratio is far more precise than either cost (10% per rollout, 2.2% for the mean of 20).
  EXPECT_LT(std::sqrt(var), 0.01);
}

TEST(NormalisedCost, IsExactOnSmallCasesAndSaysWhenItCannotEstimate) {
  const NormalisedCost same = normalised_cost({2.0, 4.0}, {2.0, 4.0});
  EXPECT_DOUBLE_EQ(same.value, 1.0);
  EXPECT_DOUBLE_EQ(same.standard_error, 0.0);
  // a = (3, 3), b = (2, 4): R = 1, d = (1, -1), se = sqrt(2 / 2) / 3.
  const NormalisedCost c = normalised_cost({3.0, 3.0}, {2.0, 4.0});
  EXPECT_DOUBLE_EQ(c.value, 1.0);
  EXPECT_DOUBLE_EQ(c.standard_error, 1.0 / 3.0);
  EXPECT_EQ(normalised_cost({5.0}, {4.0}).standard_error, -1.0);
  EXPECT_THROW(normalised_cost({1.0, 2.0}, {1.0}), std::invalid_argument);
  EXPECT_THROW(normalised_cost({}, {}), std::invalid_argument);
  EXPECT_THROW(normalised_cost({1.0}, {0.0}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
