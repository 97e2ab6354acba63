// delay_controls (input_delay.hpp): u_applied(t) = (1 - f) u(t - D) + f u(t - D - 1), the first
// command held before the record began; checked against values written out by hand.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "gpilqg/core/input_delay.hpp"

namespace gpilqg {
namespace {

Matrix ramp() {
  Matrix u(5, 2);
  u << 0, 10, 1, 11, 2, 12, 3, 13, 4, 14;
  return u;
}

TEST(InputDelay, ZeroDelayIsTheCommand) { EXPECT_EQ(delay_controls(ramp(), 0.0), ramp()); }

TEST(InputDelay, AWholeDelayShiftsAndHoldsTheFirstCommand) {
  Matrix expected(5, 2);
  expected << 0, 10, 0, 10, 0, 10, 1, 11, 2, 12;
  EXPECT_EQ(delay_controls(ramp(), 2.0), expected);
}

TEST(InputDelay, AFractionalDelayInterpolatesBetweenSamples) {
  // d = 1.25: 0.75 u(t - 1) + 0.25 u(t - 2); on a ramp u(t) = t that is t - 1.25 once t >= 2.
  const Matrix applied = delay_controls(ramp(), 1.25);
  EXPECT_DOUBLE_EQ(applied(0, 0), 0.0);
  EXPECT_DOUBLE_EQ(applied(1, 0), 0.0);   // 0.75 u(0) + 0.25 u(0)
  EXPECT_DOUBLE_EQ(applied(2, 0), 0.75);  // 0.75 u(1) + 0.25 u(0)
  EXPECT_DOUBLE_EQ(applied(4, 0), 2.75);
  EXPECT_DOUBLE_EQ(applied(4, 1), 12.75);
}

TEST(InputDelay, ADelayOutsideItsRangeIsRefused) {
  for (double d : {-0.5, kMaxInputDelay + 1.0, std::numeric_limits<double>::quiet_NaN()})
    EXPECT_THROW(delay_controls(ramp(), d), std::invalid_argument) << d;
}

}  // namespace
}  // namespace gpilqg
