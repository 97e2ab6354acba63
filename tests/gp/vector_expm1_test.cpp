/// detail::expm1_in_place (gp/src/vector_expm1.hpp) against glibc's scalar std::expm1, for every
/// instruction set this build and processor support: the vector functions promise at most 4 ulp, and
/// the moment matching relies on expm1's relative accuracy near 0 (its centred covariance sums
/// expm1(D) with |D| down to 1e-300). Array lengths that are not a multiple of the lane count exercise
/// the scalar tail.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../gp/src/vector_expm1.hpp"

namespace gpilqg::gp::detail {
namespace {

/// Arguments from every range the moment matching meets: tiny of both signs, O(1), large negative
/// (expm1 -> -1), large positive up to its cap of 700, and the exact values 0 and -0.
std::vector<double> test_arguments() {
  std::vector<double> x = {0.0, -0.0, 1e-300, -1e-300, 1e-17, -1e-17, 1e-9, 0.5, -0.5, 700.0, -745.0, -800.0};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> exponent(-300.0, 2.8);
  std::bernoulli_distribution negative(0.5);
  for (int i = 0; i < 4000; ++i) {
    const double v = std::pow(10.0, exponent(rng));  // up to about 630
    x.push_back(negative(rng) ? -v : v);
  }
  x.push_back(3.0);  // 4,013 values: not a multiple of 2, 4 or 8
  return x;
}

/// |a - b| in units of the spacing of doubles at b.
double ulps(double a, double b) {
  if (a == b) return 0.0;
  const double spacing = std::nextafter(std::abs(b), std::numeric_limits<double>::infinity()) - std::abs(b);
  return std::abs(a - b) / spacing;
}

TEST(VectorExpm1, EveryInstructionSetAgreesWithScalarGlibcWithinItsUlpBound) {
  const std::vector<double> x = test_arguments();
  int kinds = 0;
  for (VectorIsa isa : {VectorIsa::Scalar, VectorIsa::Sse2, VectorIsa::Avx2, VectorIsa::Avx512}) {
    if (!supported(isa)) continue;
    ++kinds;
    std::vector<double> y = x;
    expm1_in_place(y, isa);
    double worst = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double reference = std::expm1(x[i]);
      ASSERT_TRUE(std::isfinite(y[i])) << to_string(isa) << " at x = " << x[i];
      // 4 ulp for the vector function, 1 for glibc's own scalar error.
      ASSERT_LE(ulps(y[i], reference), 5.0) << to_string(isa) << " at x = " << x[i] << ": " << y[i]
                                           << " against " << reference;
      worst = std::max(worst, ulps(y[i], reference));
    }
    // Signs of zero and the saturation at -1 hold exactly.
    EXPECT_EQ(y[0], 0.0);
    EXPECT_TRUE(std::signbit(y[1])) << to_string(isa);
    EXPECT_EQ(y[11], -1.0) << to_string(isa);
    RecordProperty(std::string("worst_ulps_") + std::string(to_string(isa)), std::to_string(worst));
  }
  EXPECT_GE(kinds, 1);
  EXPECT_TRUE(supported(widest_supported_isa()));
}

TEST(VectorExpm1, DefaultUsesTheWidestSupportedKindAndShortArraysWork) {
  for (std::size_t n : {0u, 1u, 3u, 7u, 9u}) {
    std::vector<double> y(n, -0.25), z(n, -0.25);
    expm1_in_place(y);
    expm1_in_place(z, widest_supported_isa());
    EXPECT_EQ(y, z) << "n = " << n;
    for (double v : y) EXPECT_NEAR(v, std::expm1(-0.25), 1e-15);
  }
}

TEST(VectorExpm1, AnUnsupportedKindIsRefusedNamingIt) {
  if (widest_supported_isa() == VectorIsa::Avx512) GTEST_SKIP() << "every kind is supported here";
  std::vector<double> y(4, 1.0);
  try {
    expm1_in_place(y, VectorIsa::Avx512);
    ADD_FAILURE() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'avx512' is not supported"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gpilqg::gp::detail
