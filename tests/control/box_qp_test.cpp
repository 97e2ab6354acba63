// The projected-Newton box QP against an independent brute-force solution (enumerating active sets
// and checking the KKT conditions), plus its failure status on an indefinite Hessian.

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "gpilqg/control/box_qp.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

/// Minimiser by enumeration: for every assignment of each variable to {free, lower, upper}, solve the
/// free block, keep the feasible points, return the one with the smallest objective.
Vector brute_force(const Matrix& H, const Vector& g, const Vector& lo, const Vector& hi) {
  const int n = static_cast<int>(g.size());
  int combinations = 1;
  for (int i = 0; i < n; ++i) combinations *= 3;
  double best = std::numeric_limits<double>::infinity();
  Vector best_x;
  for (int code = 0; code < combinations; ++code) {
    Vector x = Vector::Zero(n);
    std::vector<int> free;
    int c = code;
    for (int i = 0; i < n; ++i, c /= 3) {
      if (c % 3 == 0) free.push_back(i);
      else x(i) = (c % 3 == 1) ? lo(i) : hi(i);
    }
    if (!free.empty()) {
      const int f = static_cast<int>(free.size());
      Matrix Hff(f, f);
      Vector rhs(f);
      for (int a = 0; a < f; ++a) {
        rhs(a) = -g(free[a]);
        for (int i = 0; i < n; ++i)
          if (std::find(free.begin(), free.end(), i) == free.end()) rhs(a) -= H(free[a], i) * x(i);
        for (int b = 0; b < f; ++b) Hff(a, b) = H(free[a], free[b]);
      }
      const Vector xf = Hff.ldlt().solve(rhs);
      for (int a = 0; a < f; ++a) x(free[a]) = xf(a);
    }
    if (((x - lo).array() < -1e-12).any() || ((x - hi).array() > 1e-12).any()) continue;
    const double value = 0.5 * x.dot(H * x) + g.dot(x);
    if (value < best) {
      best = value;
      best_x = x;
    }
  }
  return best_x;
}

TEST(BoxQp, MatchesBruteForceOnRandomProblems) {
  for (unsigned seed = 0; seed < 40; ++seed) {
    const int n = 1 + static_cast<int>(seed % 4);
    const Matrix L = test::random_vector(n * n, -1, 1, seed).reshaped(n, n);
    const Matrix H = L * L.transpose() + 0.1 * Matrix::Identity(n, n);
    const Vector g = test::random_vector(n, -3, 3, seed + 100);
    const Vector lo = test::random_vector(n, -1.0, -0.1, seed + 200);
    const Vector hi = test::random_vector(n, 0.1, 1.0, seed + 300);
    BoxQpResult r;
    solve_box_qp(H, g, lo, hi, Vector::Zero(n), r);
    ASSERT_TRUE(usable(r.status)) << "seed " << seed;
    EXPECT_TRUE(test::matrices_near(r.x, brute_force(H, g, lo, hi), 1e-7)) << "seed " << seed;
    // Free variables are exactly those strictly inside or at a bound with zero outward gradient.
    const Vector grad = H * r.x + g;
    for (int i = 0; i < n; ++i) {
      if (r.free(i)) {
        EXPECT_NEAR(grad(i), 0.0, 1e-6) << "seed " << seed << " variable " << i;
      }
    }
  }
}

TEST(BoxQp, WithoutActiveBoundsItIsTheNewtonStep) {
  Matrix H(2, 2);
  H << 2, 0.5, 0.5, 1;
  const Vector g = Vector(Eigen::Vector2d(0.1, -0.2));
  BoxQpResult r;
  const double inf = std::numeric_limits<double>::infinity();
  solve_box_qp(H, g, Vector::Constant(2, -inf), Vector::Constant(2, inf), Vector::Zero(2), r);
  EXPECT_TRUE(test::matrices_near(r.x, Vector(-H.ldlt().solve(g)), 1e-14));
  EXPECT_TRUE(r.free.all());
}

TEST(BoxQp, AllClampedAndIndefiniteCasesAreReported) {
  BoxQpResult r;
  solve_box_qp(Matrix::Identity(2, 2), Vector::Constant(2, 10.0), Vector::Constant(2, -1.0), Vector::Constant(2, 1.0),
               Vector::Zero(2), r);
  EXPECT_EQ(r.status, BoxQpStatus::AllClamped);
  EXPECT_TRUE(test::matrices_near(r.x, Vector::Constant(2, -1.0), 0.0));
  Matrix indefinite(2, 2);
  indefinite << 1, 0, 0, -1;
  solve_box_qp(indefinite, Vector::Constant(2, 0.1), Vector::Constant(2, -1.0), Vector::Constant(2, 1.0),
               Vector::Zero(2), r);
  EXPECT_EQ(r.status, BoxQpStatus::NotPositiveDefinite);
  EXPECT_FALSE(usable(r.status));
}

}  // namespace
}  // namespace gpilqg
