/// FitOptions::max_seconds: a fit whose evaluations take longer than the limit stops at its next
/// evaluation past it with the best point so far (FitTermination::TimeLimit), begins no further start,
/// and 0 means no limit; a negative or NaN limit is refused naming the field.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "gpilqg/gp/fit.hpp"

namespace gpilqg::gp {
namespace {

/// Rosenbrock's function in 2 parameters (L-BFGS needs a few dozen evaluations from (-1.2, 1)), each
/// evaluation `pause` long; remembers the lowest value it returned.
class SlowRosenbrock final : public MarginalLikelihoodObjective {
 public:
  explicit SlowRosenbrock(std::chrono::milliseconds pause) : pause_(pause) {}
  int parameter_count() const override { return 2; }
  int input_dim() const override { return 0; }
  ParameterBounds bounds() const override { return {Vector::Constant(2, -5.0), Vector::Constant(2, 5.0)}; }
  Vector initial_parameters() const override { return Vector{{-1.2, 1.0}}; }
  NlmlEvaluation evaluate(const VectorCRef& x, Vector* gradient) override {
    std::this_thread::sleep_for(pause_);
    const double a = 1.0 - x(0), b = x(1) - x(0) * x(0);
    if (gradient != nullptr) *gradient = Vector{{-2.0 * a - 400.0 * x(0) * b, 200.0 * b}};
    const double value = a * a + 100.0 * b * b;
    lowest = std::min(lowest, value);
    return {value, FactorStatus::Ok, 0.0};
  }
  double lowest = std::numeric_limits<double>::infinity();

 private:
  std::chrono::milliseconds pause_;
};

TEST(FitTimeLimit, StopsAtTheNextEvaluationPastTheLimitWithTheBestPointSoFar) {
  SlowRosenbrock objective(std::chrono::milliseconds(20));
  FitOptions options;
  options.restarts = 3;
  options.max_evaluations = 1000;
  options.max_seconds = 0.2;
  const auto start = std::chrono::steady_clock::now();
  const ParameterFit fit = fit_parameters(objective, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(fit.summary.termination, FitTermination::TimeLimit);
  EXPECT_EQ(fit.summary.starts, 1);  // the restarts never began
  // At least 20 ms each: at most 0.2 / 0.02 = 10 evaluations fit in the limit, plus the one past it.
  EXPECT_GE(fit.summary.evaluations, 2);
  EXPECT_LE(fit.summary.evaluations, 11);
  EXPECT_LT(seconds, 0.2 + 0.2);
  EXPECT_EQ(fit.summary.nlml, objective.lowest);
  EXPECT_LT(fit.summary.nlml, fit.summary.initial_nlml);
  EXPECT_EQ(to_string(fit.summary.termination), "time limit reached");
}

TEST(FitTimeLimit, ZeroMeansNoLimitAndBadLimitsAreRefused) {
  SlowRosenbrock objective(std::chrono::milliseconds(0));
  FitOptions options;
  options.restarts = 0;
  options.max_evaluations = 500;
  const ParameterFit fit = fit_parameters(objective, options);
  EXPECT_NE(fit.summary.termination, FitTermination::TimeLimit);
  EXPECT_LT(fit.summary.nlml, 1e-8);
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    options.max_seconds = bad;
    try {
      (void)fit_parameters(objective, options);
      ADD_FAILURE() << "expected an error for " << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("FitOptions::max_seconds"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace gpilqg::gp
