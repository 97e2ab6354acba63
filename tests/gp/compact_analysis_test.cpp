/// CompactBackend::analyze (CHOLMOD's symbolic analysis before any numerical work) against counts
/// worked out by hand for patterns whose factor is known: with c_j the entries of column j of L,
/// nnz(L) = sum_j c_j and the flops sum_j c_j^2 are
///   dense K (every pair within the support):  N(N+1)/2 and N(N+1)(2N+1)/6 (~N^3/3), whatever the order;
///   diagonal K (no pair within it):           N and N;
/// the gradient's inverse subset: 3 N^3 (one supernode) and 3 N (N single-column supernodes);
///   a path (points 1 apart on a line, support radius 1.5): K tridiagonal in the points' order along
///     the line; a minimum-degree ordering eliminates from the ends without fill, so c_j = 2 but for
///     the last column: 2N - 1 and 4N - 3;
/// and against the numerical factorisation: analyze's nnz(L) is the fill the fit's factor has.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "gpilqg/gp/compact.hpp"

namespace gpilqg::gp {
namespace {

/// [log l (D); log sf; log sn] with every l = `support`.
Vector parameters(int d, double support) {
  Vector theta = Vector::Constant(d + 2, std::log(support));
  theta(d) = 0.0;
  theta(d + 1) = std::log(0.1);
  return theta;
}

TrainingSet data_with_inputs(Matrix inputs) {
  TrainingSet data;
  data.targets = Vector::LinSpaced(inputs.rows(), -1.0, 1.0);
  data.inputs = std::move(inputs);
  return data;
}

TEST(CompactAnalysis, DenseKernelMatrixCostsNCubedOverThree) {
  const int n = 120;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Matrix x(n, 3);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = u(rng);
  // Every distance is below sqrt(3) < 10: all pairs lie within the support.
  const CompactFactorAnalysis a = CompactBackend().analyze(data_with_inputs(x), parameters(3, 10.0));
  const double nn = n;
  EXPECT_FALSE(a.over_budget);
  EXPECT_EQ(a.kernel_nonzeros, n * (n + 1) / 2);
  EXPECT_EQ(a.factor_nonzeros, nn * (nn + 1) / 2);
  EXPECT_EQ(a.factorisation_flops, nn * (nn + 1) * (2 * nn + 1) / 6);
  EXPECT_NEAR(a.factorisation_flops / (nn * nn * nn / 3.0), 1.0, 2.0 / nn);
  EXPECT_EQ(a.inverse_subset_flops, 3.0 * nn * nn * nn);  // one supernode, c = N, b = 0
}

TEST(CompactAnalysis, DiagonalAndTridiagonalPatternsHaveTheirClosedForms) {
  const int n = 200;
  // Points 1 apart on a line, in a shuffled order (the ordering has to find the path).
  std::vector<int> position(n);
  std::iota(position.begin(), position.end(), 0);
  std::shuffle(position.begin(), position.end(), std::mt19937_64(8));
  Matrix x(n, 2);
  for (int i = 0; i < n; ++i) x.row(i) << position[static_cast<std::size_t>(i)], 0.25 * (i % 2);
  const TrainingSet data = data_with_inputs(x);
  const CompactBackend backend;
  // Support 0.9 < 1: no pair within it, K diagonal.
  const CompactFactorAnalysis diagonal = backend.analyze(data, parameters(2, 0.9));
  EXPECT_EQ(diagonal.kernel_nonzeros, n);
  EXPECT_EQ(diagonal.factor_nonzeros, n);
  EXPECT_EQ(diagonal.factorisation_flops, n);
  EXPECT_EQ(diagonal.inverse_subset_flops, 3.0 * n);  // N supernodes, c = 1, b = 0
  // Support 1.5: neighbours along the line 1 apart (distance <= sqrt(1 + 0.25^2) < 1.5), the next
  // ones 2 apart (> 1.5) are not.
  const CompactFactorAnalysis path = backend.analyze(data, parameters(2, 1.5));
  EXPECT_EQ(path.kernel_nonzeros, 2 * n - 1);
  EXPECT_EQ(path.factor_nonzeros, 2 * n - 1);
  EXPECT_EQ(path.factorisation_flops, 4 * n - 3);
}

TEST(CompactAnalysis, ABudgetTooSmallForThePatternIsReportedNotAnalysed) {
  Matrix x(50, 1);
  for (int i = 0; i < 50; ++i) x(i, 0) = 0.01 * i;
  CompactOptions options;
  options.max_factor_nonzeros = 100;  // the dense pattern has 1275 entries
  const CompactFactorAnalysis a = CompactBackend(options).analyze(data_with_inputs(x), parameters(1, 10.0));
  EXPECT_TRUE(a.over_budget);
  EXPECT_EQ(a.factorisation_flops, 0.0);
  EXPECT_THROW((void)CompactBackend().analyze(data_with_inputs(x), parameters(2, 1.0)), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg::gp
