/// Properties every backend must have, as typed tests over BackendCases (gp_test_support.hpp):
/// analytic gradients equal central differences, the prior returns far from the data, degenerate data
/// is rejected with a clear message, save/load reproduces the model, and fitting lowers the NLML.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gp_test_support.hpp"
#include "gpilqg/gp/gp_io.hpp"

namespace gpilqg::gp::test {
namespace {

/// Only a fitted model can predict (docs/architecture.md#conventions-of-the-code), checked at compile
/// time.
template <class T>
concept CanPredict = requires(const T& t, const Vector& z, Prediction& p) { t.predict(z, p); };
static_assert(CanPredict<FittedGp>);
static_assert(!CanPredict<GpBackend>);

template <class Case>
class BackendTest : public ::testing::Test {
 protected:
  void SetUp() override {
    oracle_ = load_oracle();
    backend_ = Case::make();
  }
  OracleData oracle_;
  std::unique_ptr<GpBackend> backend_;
};

TYPED_TEST_SUITE(BackendTest, BackendCases);

TYPED_TEST(BackendTest, NlmlGradientMatchesCentralDifferences) {
  const TrainingSet& data = this->oracle_.train;
  auto objective = this->backend_->objective(data, FitOptions{});
  Vector theta = parameters_for(*this->backend_, data, this->oracle_.hyp);
  // A second point away from the reference hyperparameters, to exercise every term.
  Vector shifted = theta;
  shifted.head(5) += Vector::LinSpaced(5, -0.3, 0.4);
  for (const Vector& point : {theta, shifted}) {
    Vector gradient;
    ASSERT_NE(objective->evaluate(point, &gradient).status, FactorStatus::Failed);
    const Matrix numeric = ::gpilqg::test::numeric_jacobian(
        [&](const Vector& t) {
          Vector v(1);
          v(0) = objective->evaluate(t, nullptr).value;
          return v;
        },
        point, 1e-5);
    EXPECT_TRUE(matrices_near(gradient.transpose(), numeric, 1e-6, TypeParam::gradient_tolerance));
  }
}

TYPED_TEST(BackendTest, PredictionGradientsMatchCentralDifferences) {
  const auto model = this->backend_->condition(this->oracle_.train,
                                               parameters_for(*this->backend_, this->oracle_.train, this->oracle_.hyp));
  Prediction p, probe;
  for (Eigen::Index s = 0; s < this->oracle_.test_inputs.rows(); ++s) {
    const Vector z = this->oracle_.test_inputs.row(s).transpose();
    model->predict(z, p, PredictionRequest{true, true});
    const Matrix numeric = ::gpilqg::test::numeric_jacobian(
        [&](const Vector& at) {
          model->predict(at, probe);
          Vector v(2);
          v << probe.mean, probe.variance;
          return v;
        },
        z, 1e-6);
    EXPECT_TRUE(matrices_near(p.mean_gradient.transpose(), numeric.row(0), 1e-8, 1e-6));
    EXPECT_TRUE(matrices_near(p.variance_gradient.transpose(), numeric.row(1), 1e-8, 1e-6));
    // Asking for less gives the same numbers.
    Prediction mean_only;
    model->predict(z, mean_only, PredictionRequest{false, false});
    EXPECT_EQ(mean_only.mean, p.mean);
  }
}

TYPED_TEST(BackendTest, FarFromDataMeanIsPriorAndVarianceIsPriorVariance) {
  if constexpr (!TypeParam::reverts_to_prior) GTEST_SKIP() << "this backend's variance does not revert";
  const auto model = this->backend_->condition(this->oracle_.train,
                                               parameters_for(*this->backend_, this->oracle_.train, this->oracle_.hyp));
  Prediction p;
  model->predict(Vector::Constant(3, 1e3), p, PredictionRequest{true, true});
  EXPECT_NEAR(p.mean, 0.0, 1e-12);
  EXPECT_NEAR(p.variance, model->prior_variance(), 1e-12 * model->prior_variance());
  EXPECT_TRUE(matrices_near(p.mean_gradient, Vector::Zero(3), 1e-12));
  EXPECT_TRUE(matrices_near(p.variance_gradient, Vector::Zero(3), 1e-12));
}

TYPED_TEST(BackendTest, DegenerateDataIsRejectedWithAClearMessage) {
  const TrainingSet good = this->oracle_.train;
  auto expect_error = [&](const TrainingSet& bad, const std::string& phrase) {
    try {
      (void)this->backend_->fit(bad);
      ADD_FAILURE() << "no error for data that should show '" << phrase << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
    }
  };
  TrainingSet few{good.inputs.topRows(2), good.targets.head(2)};
  expect_error(few, "only 2 points for 3 input dimensions");
  TrainingSet constant = good;
  constant.targets.setConstant(0.7);
  expect_error(constant, "targets equal 0.7");
  TrainingSet nan_input = good;
  nan_input.inputs(4, 1) = std::numeric_limits<double>::quiet_NaN();
  expect_error(nan_input, "input row 4, column 1 is nan");
  TrainingSet inf_target = good;
  inf_target.targets(3) = std::numeric_limits<double>::infinity();
  expect_error(inf_target, "target 3 is inf");
  TrainingSet mismatch{good.inputs, good.targets.head(19)};
  expect_error(mismatch, "inputs have 20 rows but there are 19 targets");
  // Parameter vectors of the wrong size are rejected too.
  EXPECT_THROW((void)this->backend_->condition(good, Vector::Zero(2)), std::invalid_argument);
  // And a test input of the wrong size.
  const auto model = this->backend_->condition(good, parameters_for(*this->backend_, good, this->oracle_.hyp));
  Prediction p;
  EXPECT_THROW(model->predict(Vector::Zero(2), p), std::invalid_argument);
}

TYPED_TEST(BackendTest, SaveAndLoadReproduceTheModel) {
  const auto model = this->backend_->condition(this->oracle_.train,
                                               parameters_for(*this->backend_, this->oracle_.train, this->oracle_.hyp));
  const auto file = ::gpilqg::test::temporary_dir("gp_io") / "model.h5";
  save_fitted_gp(file, "/gp/output_0", *model);
  save_fitted_gp(file, "/gp/output_0", *model);  // replacing a group works
  const auto loaded = load_fitted_gp(file, "gp/output_0", *this->backend_);
  EXPECT_EQ(loaded->backend_name(), model->backend_name());
  EXPECT_EQ(loaded->parameters(), model->parameters());
  Vector m1, v1, m2, v2;
  model->predict(this->oracle_.test_inputs, m1, v1);
  loaded->predict(this->oracle_.test_inputs, m2, v2);
  EXPECT_EQ(m1, m2);
  EXPECT_EQ(v1, v2);
  EXPECT_THROW((void)load_fitted_gp(file, "/gp/missing", *this->backend_), std::runtime_error);
  EXPECT_THROW((void)load_fitted_gp(file.parent_path() / "absent.h5", "/gp/output_0", *this->backend_),
               std::runtime_error);
}

TYPED_TEST(BackendTest, FitLowersTheNlmlAndIsDeterministic) {
  FitOptions options;
  options.restarts = 1;
  const FitResult a = this->backend_->fit(this->oracle_.train, options);
  const FitResult b = this->backend_->fit(this->oracle_.train, options);
  EXPECT_LT(a.summary.nlml, a.summary.initial_nlml) << a.summary.one_line();
  EXPECT_EQ(a.model->parameters(), b.model->parameters());
  EXPECT_TRUE(std::isfinite(a.summary.nlml));
  EXPECT_GT(a.summary.evaluations, 0);
  EXPECT_EQ(a.summary.starts, 2);
  // A warm start from the fit is tried first and ends at (or near) the same optimum.
  options.warm_start = a.model->parameters();
  const FitResult warm = this->backend_->fit(this->oracle_.train, options);
  EXPECT_LE(warm.summary.nlml, a.summary.nlml + 1e-6);
}

}  // namespace
}  // namespace gpilqg::gp::test
