/// The exact GP against independent golden numbers: GPML 4.2 (Octave) and scikit-learn / NumPy, from
/// tests/reference/gp_oracle (README there: provenance and tolerances).

#include <gtest/gtest.h>

#include <cmath>

#include "gp_test_support.hpp"
#include "gpilqg/gp/fit.hpp"
#include "gpilqg/gp/kernel.hpp"

namespace gpilqg::gp::test {
namespace {

class ExactOracle : public ::testing::Test {
 protected:
  void SetUp() override {
    oracle_ = load_oracle();
    gpml_ = load_oracle_json("gpml");
    python_ = load_oracle_json("python");
  }
  OracleData oracle_;
  nlohmann::json gpml_, python_;
  ExactGpBackend backend_{};
};

TEST_F(ExactOracle, NlmlAndGradientMatchGpml) {
  auto objective = backend_.objective(oracle_.train, FitOptions{});
  Vector gradient;
  const NlmlEvaluation e = objective->evaluate(oracle_.hyp.pack(), &gradient);
  EXPECT_EQ(e.status, FactorStatus::Ok);
  const double expected = gpml_["exact"]["nlZ"].get<double>();
  EXPECT_NEAR(e.value, expected, 1e-10 * std::abs(expected));
  Matrix expected_gradient(5, 1);
  expected_gradient.topRows(4) = json_matrix(gpml_["exact"]["dnlZ_cov"]);
  expected_gradient(4, 0) = gpml_["exact"]["dnlZ_lik"].get<double>();
  EXPECT_TRUE(matrices_near(gradient, expected_gradient, 0.0, 1e-10));
  EXPECT_TRUE(matrices_near(gradient, json_matrix(python_["numpy_exact"]["dnlZ"]), 0.0, 1e-10));
}

TEST_F(ExactOracle, ZeroMeanCaseMatchesGpml) {
  // The same GP on the raw targets (no prior mean): GPML's exact_zeromean case.
  TrainingSet raw = oracle_.train;
  for (int i = 0; i < raw.size(); ++i) raw.targets(i) += sum_of_sines(raw.inputs.row(i).transpose(), nullptr);
  auto objective = backend_.objective(raw, FitOptions{});
  Vector gradient;
  const double nlz = objective->evaluate(oracle_.hyp.pack(), &gradient).value;
  const double expected = gpml_["exact_zeromean"]["nlZ"].get<double>();
  EXPECT_NEAR(nlz, expected, 1e-10 * std::abs(expected));
  EXPECT_TRUE(matrices_near(gradient.head(4), json_matrix(gpml_["exact_zeromean"]["dnlZ_cov"]), 0.0, 1e-10));
  const auto model = backend_.condition(raw, oracle_.hyp.pack());
  Vector mean, variance;
  model->predict(oracle_.test_inputs, mean, variance);
  EXPECT_TRUE(matrices_near(mean, json_matrix(gpml_["exact_zeromean"]["fmu"]), 0.0, 1e-10));
}

TEST_F(ExactOracle, PredictionsMatchGpmlAndNumpy) {
  const auto model = backend_.condition(oracle_.train, oracle_.hyp.pack());
  EXPECT_EQ(model->conditioning().status, FactorStatus::Ok);
  EXPECT_NEAR(model->negative_log_marginal_likelihood(), gpml_["exact"]["nlZ"].get<double>(), 1e-9);
  const Eigen::Index count = oracle_.test_inputs.rows();
  const int d = model->input_dim();
  Matrix mean(count, 1), variance(count, 1), noisy(count, 1), dmean(count, d), dvariance(count, d);
  Prediction p;
  for (Eigen::Index s = 0; s < count; ++s) {
    const Vector z = oracle_.test_inputs.row(s).transpose();
    model->predict(z, p, PredictionRequest{true, true});
    add_prior_mean(&sum_of_sines, z, p);
    mean(s, 0) = p.mean;
    variance(s, 0) = p.variance;
    noisy(s, 0) = p.variance + model->noise_variance();
    dmean.row(s) = p.mean_gradient.transpose();
    dvariance.row(s) = p.variance_gradient.transpose();
  }
  EXPECT_TRUE(matrices_near(mean, json_matrix(gpml_["exact"]["fmu"]), 0.0, 1e-10));
  EXPECT_TRUE(matrices_near(variance, json_matrix(gpml_["exact"]["fs2"]), 0.0, 1e-10));
  EXPECT_TRUE(matrices_near(noisy, json_matrix(gpml_["exact"]["ys2"]), 0.0, 1e-10));
  EXPECT_TRUE(matrices_near(mean, json_matrix(python_["numpy_exact"]["fmu"]), 0.0, 1e-10));
  EXPECT_TRUE(matrices_near(variance, json_matrix(python_["numpy_exact"]["fs2"]), 0.0, 1e-10));
  // Analytic prediction gradients (NumPy), and GPML's central differences to their own accuracy.
  EXPECT_TRUE(matrices_near(dmean, json_matrix(python_["numpy_exact"]["dfmu_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(dvariance, json_matrix(python_["numpy_exact"]["dfs2_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(dmean, json_matrix(gpml_["exact"]["dfmu_dxs_fd"]), 1e-8, 1e-8));
  EXPECT_TRUE(matrices_near(dvariance, json_matrix(gpml_["exact"]["dfs2_dxs_fd"]), 1e-8, 1e-8));

  // The batch path agrees with the single-point path.
  Vector batch_mean, batch_variance;
  model->predict(oracle_.test_inputs, batch_mean, batch_variance);
  for (Eigen::Index s = 0; s < count; ++s) batch_mean(s) += sum_of_sines(oracle_.test_inputs.row(s).transpose(), nullptr);
  EXPECT_TRUE(matrices_near(batch_mean, mean, 1e-13, 1e-12));
  EXPECT_TRUE(matrices_near(batch_variance, variance, 1e-13, 1e-12));
}

TEST_F(ExactOracle, MaximumLikelihoodFitReachesGpmlOptimum) {
  FitOptions options;
  options.warm_start = oracle_.hyp.pack();  // the README's fit starts from hyp.csv
  options.restarts = 0;
  const FitResult fit = backend_.fit(oracle_.fit, options);
  const double expected = gpml_["exact_ml2_fit"]["nlZ"].get<double>();
  EXPECT_NEAR(fit.summary.nlml, expected, 1e-6) << fit.summary.one_line();
  EXPECT_NEAR(fit.model->negative_log_marginal_likelihood(), expected, 1e-6);
  Vector expected_hyp(5);
  expected_hyp.head(4) = json_matrix(gpml_["exact_ml2_fit"]["hyp_cov"]).col(0);
  expected_hyp(4) = gpml_["exact_ml2_fit"]["hyp_lik"].get<double>();
  EXPECT_TRUE(matrices_near(fit.model->parameters(), expected_hyp, 1e-4));
  EXPECT_EQ(fit.summary.training_points, 200);
  EXPECT_EQ(fit.summary.conditioning.status, FactorStatus::Ok);
}

TEST_F(ExactOracle, PaperKernelConventionMapsOntoGpml) {
  // The paper's exp(-(zi - zj)' Lambda^-1 (zi - zj)) equals GPML's with Lambda = 2 l^2 (README: l = 1/sqrt(2 W)).
  const Vector lambda = (2.0 * oracle_.hyp.lengthscales().array().square()).matrix();
  const Hyperparameters h = Hyperparameters::from_paper(lambda, std::exp(oracle_.hyp.log_signal_std),
                                                        std::exp(oracle_.hyp.log_noise_std));
  EXPECT_TRUE(matrices_near(h.pack(), oracle_.hyp.pack(), 1e-14));
  const ArdSquaredExponential kernel(h);
  const Vector a = oracle_.train.inputs.row(0).transpose(), b = oracle_.train.inputs.row(1).transpose();
  const Vector r = a - b;
  const double paper = h.signal_variance() * std::exp(-(r.array().square() / lambda.array()).sum());
  EXPECT_NEAR(kernel(a, b), paper, 1e-15);
}

}  // namespace
}  // namespace gpilqg::gp::test
