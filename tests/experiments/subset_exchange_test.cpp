// The exchange of members in the greedy part of the subset search (subset_exchange.hpp), on a linear
// regression whose cross-validated scores this file computes itself: a proxy that forward growth keeps
// is exchanged for the effect it stood for, the exchanged set is the best set of its size by exhaustive
// search (a second implementation), and an exchange needs a reduction the folds agree on.

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "gpilqg/experiments/diagnosis/subset_exchange.hpp"

namespace gpilqg::diagnosis {
namespace {

/// Least squares of y on the columns `set` of X, cross-validated over K contiguous folds: what the fit
/// on the other folds leaves on each fold (sum of squares), fold by fold.
struct CrossValidated {
  Eigen::MatrixXd X;
  Eigen::VectorXd y;
  int K = 5;

  std::vector<double> operator()(const std::vector<int>& set) const {
    const Eigen::Index n = X.rows(), per = n / K;
    std::vector<double> out;
    for (int f = 0; f < K; ++f) {
      const Eigen::Index begin = f * per, end = f == K - 1 ? n : begin + per;
      Eigen::MatrixXd A(n - (end - begin), static_cast<Eigen::Index>(set.size()));
      Eigen::VectorXd b(A.rows());
      for (Eigen::Index i = 0, r = 0; i < n; ++i) {
        if (i >= begin && i < end) continue;
        for (std::size_t j = 0; j < set.size(); ++j) A(r, static_cast<Eigen::Index>(j)) = X(i, set[j]);
        b(r++) = y(i);
      }
      const Eigen::VectorXd theta = A.colPivHouseholderQr().solve(b);
      double left = 0.0;
      for (Eigen::Index i = begin; i < end; ++i) {
        double fit = 0.0;
        for (std::size_t j = 0; j < set.size(); ++j) fit += theta(static_cast<Eigen::Index>(j)) * X(i, set[j]);
        left += (y(i) - fit) * (y(i) - fit);
      }
      out.push_back(left);
    }
    return out;
  }
  double total(const std::vector<int>& set) const {
    double s = 0.0;
    for (double v : (*this)(set)) s += v;
    return s;
  }
};

/// y = x0 + x1 + noise; x2 = x0 + 0.8 x1 + 0.5 z is the proxy that is best alone (its squared
/// correlation with y is 0.86, each true column's 0.5); x3 and x4 are unrelated noise.
CrossValidated proxy_case() {
  std::mt19937_64 random(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 400;
  CrossValidated c;
  c.X.resize(n, 5);
  c.y.resize(n);
  for (int i = 0; i < n; ++i) {
    const double x0 = gauss(random), x1 = gauss(random), z = gauss(random);
    c.X.row(i) << x0, x1, x0 + 0.8 * x1 + 0.5 * z, gauss(random), gauss(random);
    c.y(i) = x0 + x1 + 0.05 * gauss(random);
  }
  return c;
}

/// Forward growth by one: the candidate outside `set` of the least total score.
std::vector<int> grown(const CrossValidated& c, std::vector<int> set) {
  double least = std::numeric_limits<double>::infinity();
  int best = -1;
  for (int j = 0; j < c.X.cols(); ++j) {
    if (std::find(set.begin(), set.end(), j) != set.end()) continue;
    std::vector<int> trial = set;
    trial.push_back(j);
    if (const double s = c.total(trial); s < least) {
      least = s;
      best = j;
    }
  }
  set.push_back(best);
  return set;
}

const MayJoin kAny = [](int, int) { return true; };

TEST(SubsetExchange, TheProxyThatGrowthKeepsIsExchangedForTheEffectItStoodFor) {
  const CrossValidated c = proxy_case();
  const std::vector<int> one = grown(c, {});
  ASSERT_EQ(one, std::vector<int>{2});  // the premise: the proxy is the best single column
  const std::vector<int> two = grown(c, one);
  ASSERT_EQ(two.front(), 2);            // and growth keeps it
  std::vector<Exchange> made;
  const std::vector<int> out = exchanged(c, 5, two, kAny, 4, &made);
  ASSERT_EQ(made.size(), 1u);
  EXPECT_EQ(made[0].out, 2);
  std::vector<int> sorted = out;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<int>{0, 1}));
  EXPECT_EQ(out[1], two[1]);  // the member not exchanged keeps its place

  // The best pair by exhaustive search over all 10 pairs is the same.
  double least = std::numeric_limits<double>::infinity();
  std::vector<int> best;
  for (int a = 0; a < 5; ++a)
    for (int b = a + 1; b < 5; ++b)
      if (const double s = c.total({a, b}); s < least) {
        least = s;
        best = {a, b};
      }
  EXPECT_EQ(best, sorted);
  // What the exchanged pair leaves is the noise, 0.05^2 per row; the pair with the proxy leaves 80 times more.
  EXPECT_NEAR(c.total(out) / 400.0, 0.0025, 0.25 * 0.0025);
  EXPECT_GT(c.total(two), 50.0 * c.total(out));
}

TEST(SubsetExchange, NoExchangeForACopyOrACandidateThatMayNotJoin) {
  CrossValidated c = proxy_case();
  // A sixth column equal to x0: exchanging x0 for it leaves every fold's score as it was.
  c.X.conservativeResize(Eigen::NoChange, 6);
  c.X.col(5) = c.X.col(0);
  std::vector<Exchange> made;
  EXPECT_EQ(exchanged(c, 6, {0, 1}, kAny, 4, &made), (std::vector<int>{0, 1}));
  EXPECT_TRUE(made.empty());
  made.clear();
  // Candidates that may not join: the proxy stays when x1 may be in no set with x0 or its copy.
  const MayJoin apart = [](int a, int b) {
    const auto x0 = [](int i) { return i == 0 || i == 5; };
    return !((x0(a) && b == 1) || (a == 1 && x0(b)));
  };
  const std::vector<int> kept = exchanged(c, 6, {2, 1}, apart, 4, &made);
  EXPECT_NE(std::find(kept.begin(), kept.end(), 1), kept.end());
  EXPECT_EQ(std::find(kept.begin(), kept.end(), 0), kept.end());
  EXPECT_EQ(std::find(kept.begin(), kept.end(), 5), kept.end());  // nor its copy
  for (const Exchange& e : made) EXPECT_TRUE(e.in != 0 && e.in != 5) << e.in;
}

/// Scores fold by fold set by hand, the others (5 folds of 10) for every set not listed.
FoldScores scripted(std::vector<std::pair<std::vector<int>, std::vector<double>>> table) {
  return [table = std::move(table)](const std::vector<int>& set) {
    for (const auto& [listed, scores] : table)
      if (listed == set) return scores;
    return std::vector<double>(5, 10.0);
  };
}

TEST(SubsetExchange, TheExchangeOfTheLeastScoreThatPassesTheRuleIsMade) {
  // From {0, 1}: exchanging 0 for 2 lowers the total most (50 -> 45), but on one fold alone, raising
  // the others (d = -0.5, -0.5, -0.5, -0.5, 7: D = 5 against sqrt(5 / 4 * 45) = 7.5); 0 for 3 lowers it
  // to 45.5, by 0.9 on every fold alike, and 1 for 4 by 1e-12 of the score on every fold (rounding).
  // So 0 -> 3.
  const FoldScores folds = scripted({{{2, 1}, {10.5, 10.5, 10.5, 10.5, 3}},
                                     {{3, 1}, {9.1, 9.1, 9.1, 9.1, 9.1}},
                                     {{0, 4}, {10 - 1e-11, 10 - 1e-11, 10 - 1e-11, 10 - 1e-11, 10 - 1e-11}}});
  std::vector<Exchange> made;
  EXPECT_EQ(exchanged(folds, 5, {0, 1}, kAny, 4, &made), (std::vector<int>{3, 1}));
  ASSERT_EQ(made.size(), 1u);
  EXPECT_EQ(made[0].out, 0);
  EXPECT_EQ(made[0].in, 3);
  // Without candidate 3 (it may be in no set), no exchange passes: the one-fold drop and the rounding fail.
  const MayJoin no_three = [](int a, int b) { return a != 3 && b != 3; };
  made.clear();
  EXPECT_EQ(exchanged(folds, 5, {0, 1}, no_three, 4, &made), (std::vector<int>{0, 1}));
  EXPECT_TRUE(made.empty());
  // At most max_rounds exchanges: 0 -> 3, then 1 -> 4 from {3, 1}, would be two; one round makes one.
  const FoldScores chain = scripted({{{3, 1}, {9, 9, 9, 9, 9}}, {{3, 4}, {8, 8, 8, 8, 8}}});
  made.clear();
  EXPECT_EQ(exchanged(chain, 5, {0, 1}, kAny, 1, &made), (std::vector<int>{3, 1}));
  EXPECT_EQ(made.size(), 1u);
  made.clear();
  EXPECT_EQ(exchanged(chain, 5, {0, 1}, kAny, 4, &made), (std::vector<int>{3, 4}));
  EXPECT_EQ(made.size(), 2u);
}

TEST(SubsetExchange, TheOneStandardErrorRuleAgainstItsClosedForm) {
  // d = (1, 1, 1, 1): D = 4, no spread.
  EXPECT_TRUE(lowers_by_more_than_its_error({10, 10, 10, 10}, {9, 9, 9, 9}));
  // d = (5, -5, 0, 4): D = 4, sum (d - 1)^2 = 16 + 36 + 1 + 9 = 62, sqrt(4 / 3 * 62) = 9.09 > 4.
  EXPECT_FALSE(lowers_by_more_than_its_error({10, 10, 10, 10}, {5, 15, 10, 6}));
  // d = (3, 2, 3, 2): D = 10, sum (d - 2.5)^2 = 1, sqrt(4 / 3) = 1.15 < 10.
  EXPECT_TRUE(lowers_by_more_than_its_error({10, 10, 10, 10}, {7, 8, 7, 8}));
  EXPECT_FALSE(lowers_by_more_than_its_error({10}, {10}));  // one fold: any reduction, and none here
  EXPECT_TRUE(lowers_by_more_than_its_error({10}, {9.5}));
  // A reduction of 4e-13 of the score on every fold: the folds agree, but it is rounding.
  EXPECT_FALSE(lowers_by_more_than_its_error({10, 10, 10, 10}, {10 - 4e-12, 10 - 4e-12, 10 - 4e-12, 10 - 4e-12}));
  EXPECT_TRUE(lowers_by_more_than_its_error({10, 10, 10, 10}, {10 - 4e-6, 10 - 4e-6, 10 - 4e-6, 10 - 4e-6}));
  EXPECT_THROW(lowers_by_more_than_its_error({10, 10}, {9}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg::diagnosis
