/// Numerical faults of GP regression, for every backend of the registry (exact, FITC, SSGP): each one
/// gets a documented recovery (noise floor, jitter reported in ConditioningReport / FitSummary) or a
/// clear error, and never a NaN in a fit or a prediction (README "Reliability").

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gp_test_support.hpp"
#include "gpilqg/core/finite_difference.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp::test {
namespace {

class NumericalFault : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<GpBackend> backend() const {
    BackendSettings settings;
    settings.inducing = 15;
    settings.frequencies = 15;
    return make_backend(GetParam(), settings);
  }
  static FitOptions quick() {
    FitOptions options;
    options.restarts = 0;
    options.max_evaluations = 80;
    return options;
  }
};

/// Mean, variance and both gradients are finite (variance >= 0) at every row of `points`.
::testing::AssertionResult predictions_finite(const FittedGp& model, const Matrix& points) {
  Prediction p;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    model.predict(points.row(i).transpose(), p, PredictionRequest{true, true});
    if (!std::isfinite(p.mean) || !std::isfinite(p.variance) || p.variance < 0.0 || !p.mean_gradient.allFinite() ||
        !p.variance_gradient.allFinite())
      return ::testing::AssertionFailure() << "at row " << i << ": mean " << p.mean << ", variance " << p.variance;
  }
  return ::testing::AssertionSuccess();
}

/// Root-mean-square error of the predicted mean against f at the rows of `points`.
template <class F>
double rmse(const FittedGp& model, const Matrix& points, F&& f) {
  Prediction p;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Vector z = points.row(i).transpose();
    model.predict(z, p, PredictionRequest{false, false});
    sum += (p.mean - f(z)) * (p.mean - f(z));
  }
  return std::sqrt(sum / static_cast<double>(points.rows()));
}

/// 30 distinct inputs in [-3, 3], each given three times, with noise-free targets sin(x).
TrainingSet triplicated_sine() {
  TrainingSet data;
  data.inputs.resize(90, 1);
  data.targets.resize(90);
  for (int i = 0; i < 90; ++i) {
    const double x = -3.0 + 6.0 * static_cast<double>(i % 30) / 29.0;
    data.inputs(i, 0) = x;
    data.targets(i) = std::sin(x);
  }
  return data;
}

Matrix grid(int count, double lo, double hi) {
  return Vector::LinSpaced(count, lo, hi);
}

TEST_P(NumericalFault, DuplicatedInputsFitAndPredictAccurately) {
  const TrainingSet data = triplicated_sine();
  const FitResult fit = backend()->fit(data, quick());
  EXPECT_TRUE(std::isfinite(fit.summary.nlml)) << fit.summary.one_line();
  EXPECT_TRUE(fit.model->parameters().allFinite());
  EXPECT_NE(fit.model->conditioning().status, FactorStatus::Failed);
  const Matrix test = grid(41, -2.5, 2.5);
  EXPECT_TRUE(predictions_finite(*fit.model, test));
  EXPECT_LT(rmse(*fit.model, test, [](const Vector& z) { return std::sin(z(0)); }), 0.05) << fit.summary.one_line();
}

TEST_P(NumericalFault, DuplicatedInputsWithoutANoiseFloorGetReportedJitter) {
  // Noise 1e-12 on exact duplicates: K (exact) is singular; whatever a backend needs is reported.
  const TrainingSet data = triplicated_sine();
  const auto b = backend();
  Vector theta = b->objective(data, FitOptions{})->initial_parameters();
  theta(2) = std::log(1e-12);  // [log l, log sf, log sn, extras]
  const auto model = b->condition(data, theta);
  const ConditioningReport& report = model->conditioning();
  EXPECT_NE(report.status, FactorStatus::Failed);
  EXPECT_EQ(report.status == FactorStatus::JitterAdded, report.jitter > 0.0);
  if (GetParam() == "exact") {
    EXPECT_EQ(report.status, FactorStatus::JitterAdded);
  }
  EXPECT_TRUE(std::isfinite(report.negative_log_marginal_likelihood));
  EXPECT_TRUE(predictions_finite(*model, grid(21, -4.0, 4.0)));
}

TEST_P(NumericalFault, ConstantTargetsAreAClearError) {
  TrainingSet data = triplicated_sine();
  data.targets.setConstant(0.25);
  try {
    (void)backend()->fit(data, quick());
    ADD_FAILURE() << "constant targets were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("all 90 targets equal 0.25; expected targets that vary"), std::string::npos)
        << e.what();
  }
}

TEST_P(NumericalFault, TargetsThatBarelyVaryStillFitFinitely) {
  // A spread of 1e-10 is not constant: the data-driven bounds scale with it, nothing overflows.
  TrainingSet data = triplicated_sine();
  data.targets = 3.0 + 1e-10 * data.targets.array();
  const FitResult fit = backend()->fit(data, quick());
  EXPECT_TRUE(std::isfinite(fit.summary.nlml)) << fit.summary.one_line();
  EXPECT_TRUE(predictions_finite(*fit.model, grid(11, -3.0, 3.0)));
}

TEST_P(NumericalFault, InputScalesThatDifferBySixOrdersOfMagnitude) {
  // z1 in [-1000, 1000], z2 in [-1e-3, 1e-3]; the target depends on one of them at a time.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto sample = [&](int count) {
    Matrix z(count, 2);
    for (int i = 0; i < count; ++i) z.row(i) << 1e3 * unit(rng), 1e-3 * unit(rng);
    return z;
  };
  const Matrix train = sample(80), test = sample(40);
  const auto on_large = [](const Vector& z) { return std::sin(z(0) / 400.0); };
  const auto on_small = [](const Vector& z) { return std::sin(z(1) * 2500.0); };
  for (int which = 0; which < 2; ++which) {
    TrainingSet data{train, Vector(train.rows())};
    for (Eigen::Index i = 0; i < train.rows(); ++i) {
      const Vector z = train.row(i).transpose();
      data.targets(i) = which == 0 ? on_large(z) : on_small(z);
    }
    const FitResult fit = backend()->fit(data, quick());
    EXPECT_TRUE(std::isfinite(fit.summary.nlml)) << fit.summary.one_line();
    EXPECT_TRUE(predictions_finite(*fit.model, test));
    const double error = which == 0 ? rmse(*fit.model, test, on_large) : rmse(*fit.model, test, on_small);
    EXPECT_LT(error, 0.05) << (which == 0 ? "f(z1)" : "f(z2)") << ": " << fit.summary.one_line();
  }
}

TEST_P(NumericalFault, NearSingularKernelMatrixIsJitteredReportedAndFinite) {
  // 40 inputs within 4e-8 of each other and a length-scale of 10: every kernel entry equals sf^2 to
  // about 1e-17, so K is numerically of rank 1; with noise 1e-13 the factorisation needs jitter.
  TrainingSet data;
  data.inputs = Vector::LinSpaced(40, 0.0, 4e-8);
  data.targets = Vector::LinSpaced(40, -1.0, 1.0);
  const auto b = backend();
  Vector theta = b->objective(data, FitOptions{})->initial_parameters();
  theta(0) = std::log(10.0);
  theta(1) = 0.0;
  theta(2) = std::log(1e-13);
  const auto model = b->condition(data, theta);
  EXPECT_NE(model->conditioning().status, FactorStatus::Failed);
  if (GetParam() == "exact") {
    EXPECT_EQ(model->conditioning().status, FactorStatus::JitterAdded);
    EXPECT_GT(model->conditioning().jitter, 0.0);
  }
  EXPECT_TRUE(predictions_finite(*model, grid(9, -1e-7, 1e-7)));

  // Fitting from there: the summary counts the jittered evaluations and the fit is finite.
  FitOptions options = quick();
  options.min_noise_ratio = 0.0;
  options.min_noise_std = 1e-13;
  options.warm_start = theta;
  const FitResult fit = b->fit(data, options);
  EXPECT_TRUE(std::isfinite(fit.summary.nlml)) << fit.summary.one_line();
  EXPECT_TRUE(fit.model->parameters().allFinite());
  if (GetParam() == "exact") {
    EXPECT_GT(fit.summary.jittered_evaluations, 0) << fit.summary.one_line();
    EXPECT_GT(fit.summary.max_jitter, 0.0) << fit.summary.one_line();
  }
  EXPECT_TRUE(predictions_finite(*fit.model, grid(9, -1e-7, 1e-7)));
}

INSTANTIATE_TEST_SUITE_P(Registry, NumericalFault, ::testing::ValuesIn(backend_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(ResidualModelFault, ConstantResidualsOfOneStateNameTheState) {
  // A simulator that predicts state 1 exactly: its residuals are all 0, which cannot be regressed.
  auto simulator = std::make_shared<FiniteDifferenceStepModel>(
      2, 1, 0.1, [](const Vector& x, const Vector& u, Vector& next) { next = x + 0.1 * Vector::Constant(2, u(0)); });
  ResidualData data;
  data.inputs.resize(30, 3);
  data.residuals.resize(30, 2);
  for (int i = 0; i < 30; ++i) {
    data.inputs.row(i) << 0.1 * i, std::cos(i), std::sin(0.3 * i);
    data.residuals.row(i) << 0.01 * std::sin(0.1 * i), 0.0;
  }
  ResidualModelOptions options;
  options.fit = FitOptions{};
  options.fit.restarts = 0;
  options.fit.max_evaluations = 20;
  try {
    (void)ResidualModel::fit(simulator, data, ExactGpBackend(), options);
    ADD_FAILURE() << "constant residuals were accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("ResidualModel::fit: state 1 of 2: "), std::string::npos) << message;
    EXPECT_NE(message.find("targets equal 0; expected targets that vary"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace gpilqg::gp::test
