/// gp::dense_flop_rate: a plausible rate (between 0.1 and 10,000 GFLOP/s), measured once per thread
/// count and then cached; a thread count below 1 is refused naming the function.

#include <gtest/gtest.h>

#include <stdexcept>

#include "gpilqg/gp/flop_rate.hpp"

namespace gpilqg::gp {
namespace {

TEST(FlopRate, IsPlausibleAndCached) {
  const double rate = dense_flop_rate(1);
  EXPECT_GT(rate, 1e8);
  EXPECT_LT(rate, 1e13);
  EXPECT_EQ(dense_flop_rate(1), rate);  // the cached value, not a second measurement
  try {
    (void)dense_flop_rate(0);
    ADD_FAILURE() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("dense_flop_rate: threads = 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gpilqg::gp
