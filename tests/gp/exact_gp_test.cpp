/// Exact-backend specifics: numerical trouble as a reported status, the subsample, the paper's
/// re-sample rule, and the internal inverse-from-Cholesky against Eigen.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/LU>

#include "../../gp/src/dense_cholesky.hpp"
#include "gp_test_support.hpp"
#include "gpilqg/gp/fit.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "gpilqg/gp/resample.hpp"

namespace gpilqg::gp::test {
namespace {

/// y = sin(3 x1) + 0.5 x2 + noise on [-1, 1]^2.
TrainingSet smooth_data(int n, unsigned seed, double noise = 0.05) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, noise);
  TrainingSet data{Matrix(n, 2), Vector(n)};
  for (int i = 0; i < n; ++i) {
    data.inputs(i, 0) = uniform(gen);
    data.inputs(i, 1) = uniform(gen);
    data.targets(i) = std::sin(3.0 * data.inputs(i, 0)) + 0.5 * data.inputs(i, 1) + normal(gen);
  }
  return data;
}

/// Thirty points with row 7 an exact copy of row 2.
TrainingSet data_with_duplicate() {
  TrainingSet data = smooth_data(30, 3);
  data.inputs.row(7) = data.inputs.row(2);
  return data;
}

/// Length-scales 100 times the data's extent and noise 1e-13: K is numerically of rank ~3, so the
/// Cholesky factorisation meets pivots at rounding level and fails without jitter.
Vector ill_conditioned_parameters() {
  Vector theta(4);
  theta << std::log(100.0), std::log(100.0), 0.0, std::log(1e-13);
  return theta;
}

TEST(ExactGp, CholeskyFailureAddsJitterAndReportsIt) {
  const ExactGpBackend backend;
  const TrainingSet data = data_with_duplicate();
  const auto model = backend.condition(data, ill_conditioned_parameters());
  EXPECT_EQ(model->conditioning().status, FactorStatus::JitterAdded);
  EXPECT_GT(model->conditioning().jitter, 0.0);
  EXPECT_LE(model->conditioning().jitter, 1e-2);
  Prediction p;
  model->predict(data.inputs.row(2).transpose(), p, PredictionRequest{true, true});
  EXPECT_TRUE(std::isfinite(p.mean) && std::isfinite(p.variance));
  EXPECT_TRUE(p.mean_gradient.allFinite() && p.variance_gradient.allFinite());

  auto objective = backend.objective(data, FitOptions{});
  Vector gradient;
  const NlmlEvaluation e = objective->evaluate(ill_conditioned_parameters(), &gradient);
  EXPECT_EQ(e.status, FactorStatus::JitterAdded);
  EXPECT_GT(e.jitter, 0.0);
  EXPECT_TRUE(std::isfinite(e.value));
  EXPECT_TRUE(gradient.allFinite());
}

TEST(ExactGp, FactorisationThatFailsEvenWithJitterIsAStatusNeverANaN) {
  const ExactGpBackend backend;
  const TrainingSet data = data_with_duplicate();
  FitOptions options;
  options.jitter = JitterSchedule{1e-30, 1e-30, 10.0};  // far too little jitter to help
  auto objective = backend.objective(data, options);
  Vector gradient;
  const NlmlEvaluation e = objective->evaluate(ill_conditioned_parameters(), &gradient);
  EXPECT_EQ(e.status, FactorStatus::Failed);
  EXPECT_EQ(e.value, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(matrices_near(gradient, Vector::Zero(4), 0.0));
  EXPECT_THROW((void)backend.condition(data, ill_conditioned_parameters(), options.jitter), std::runtime_error);
}

TEST(ExactGp, FitOnDuplicatedInputsReportsWhatHappened) {
  const ExactGpBackend backend;
  TrainingSet data = smooth_data(40, 5);
  data.inputs.bottomRows(10) = data.inputs.topRows(10);  // ten exact duplicates
  FitOptions options;
  options.min_noise_ratio = 0.0;  // allow the start below
  options.min_noise_std = 1e-13;
  options.warm_start = ill_conditioned_parameters();
  const FitResult fit = backend.fit(data, options);
  EXPECT_TRUE(std::isfinite(fit.summary.nlml));
  EXPECT_TRUE(fit.model->parameters().allFinite());
  EXPECT_GT(fit.summary.jittered_evaluations + fit.summary.failed_evaluations, 0) << fit.summary.one_line();
  EXPECT_NE(fit.summary.one_line().find("needed jitter"), std::string::npos) << fit.summary.one_line();
}

TEST(ExactGp, SubsampleIsThreeHundredByDefaultAndCanBeAll) {
  const TrainingSet data = smooth_data(700, 9);
  EXPECT_EQ(ExactGpOptions{}.max_training_points, 300);
  const ExactGpBackend subsampled;
  const TrainingSet a = subsampled.select_training_points(data, 1);
  const TrainingSet b = subsampled.select_training_points(data, 1);
  const TrainingSet c = subsampled.select_training_points(data, 2);
  EXPECT_EQ(a.size(), 300);
  EXPECT_EQ(a.inputs, b.inputs);      // deterministic per seed
  EXPECT_NE(a.inputs, c.inputs);      // a fresh draw for another seed
  const ExactGpBackend all(ExactGpOptions{ExactGpOptions::kAllPoints});
  EXPECT_EQ(all.select_training_points(data, 1).size(), 700);
  EXPECT_THROW(ExactGpBackend(ExactGpOptions{0}), std::invalid_argument);

  // Uniformity: every index is drawn about equally often over many seeds.
  std::vector<int> counts(50, 0);
  for (std::uint64_t seed = 0; seed < 4000; ++seed)
    for (int i : uniform_subsample(50, 10, seed)) ++counts[static_cast<std::size_t>(i)];
  for (int count : counts) EXPECT_NEAR(count, 800, 5 * std::sqrt(800.0));
}

TEST(ExactGp, ResampleRuleRetriesWhenTheNewLearnerIsWorse) {
  const TrainingSet data = smooth_data(400, 11);
  const TrainingSet validation = smooth_data(200, 12);
  FitOptions options;
  options.restarts = 0;
  // An excellent previous learner (all 400 points) that a 12-point subsample cannot beat.
  const auto previous = ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints}).fit(data, options).model;
  const ExactGpBackend tiny(ExactGpOptions{12});
  ResampleReport report;
  const FitResult worse = fit_with_resampling(tiny, data, validation, previous.get(), options, ResampleOptions{2}, &report);
  EXPECT_EQ(report.validation_mse.size(), 3u) << report.one_line();
  EXPECT_FALSE(report.improved);
  EXPECT_GT(report.previous_validation_mse, 0.0);
  EXPECT_NEAR(validation_mse(*worse.model, validation),
              report.validation_mse[static_cast<std::size_t>(report.chosen_attempt)], 1e-12);
  for (double e : report.validation_mse) EXPECT_GE(e, report.validation_mse[static_cast<std::size_t>(report.chosen_attempt)]);
  EXPECT_NE(report.one_line().find("WORSE"), std::string::npos);

  // A poor previous learner is beaten at once: one attempt.
  const auto poor = tiny.fit(data, options).model;
  const ExactGpBackend good;
  const FitResult better = fit_with_resampling(good, data, validation, poor.get(), options, ResampleOptions{2}, &report);
  EXPECT_EQ(report.validation_mse.size(), 1u) << report.one_line();
  EXPECT_TRUE(report.improved);
  EXPECT_LE(report.validation_mse[0], report.previous_validation_mse);
}

// A known noise variance c at every point is a homoscedastic noise sn'^2 = sn^2 + c: the same NLML,
// the same length-scale and signal gradients, and a noise gradient in the ratio sn^2 / sn'^2 (the
// learned part's share); with known variances that vary, the subsample and a saved model keep them.
TEST(ExactGp, AConstantKnownNoiseIsAHomoscedasticNoiseOfTheSumAndSubsetsAndFilesKeepIt) {
  const ExactGpBackend backend(ExactGpOptions{ExactGpOptions::kAllPoints, 1});
  const TrainingSet plain = smooth_data(60, 11);
  TrainingSet known = plain;
  const double c = 0.03, sn = 0.1;
  known.noise_variance = Vector::Constant(plain.size(), c);
  Vector theta(4), theta_sum(4);
  theta << std::log(0.6), std::log(0.9), std::log(1.1), std::log(sn);
  theta_sum = theta;
  theta_sum(3) = 0.5 * std::log(sn * sn + c);
  Vector g_known, g_sum;
  const double nlml_known = backend.objective(known, FitOptions{})->evaluate(theta, &g_known).value;
  const double nlml_sum = backend.objective(plain, FitOptions{})->evaluate(theta_sum, &g_sum).value;
  EXPECT_NEAR(nlml_known, nlml_sum, 1e-10 * std::abs(nlml_sum));
  EXPECT_MATRIX_NEAR(g_known.head(3), g_sum.head(3), 1e-9);
  EXPECT_NEAR(g_known(3), g_sum(3) * sn * sn / (sn * sn + c), 1e-9);
  EXPECT_GT(std::abs(g_sum(3)), 0.1);  // a noise gradient that can tell

  // Varying known noise: a subset keeps each point's own, and so does a saved model.
  for (int i = 0; i < known.size(); ++i) known.noise_variance(i) = 0.001 * i;
  const TrainingSet some = known.subset({5, 17, 42});
  EXPECT_EQ(some.noise_variance, (Vector(3) << 0.005, 0.017, 0.042).finished());
  const auto model = backend.condition(known, theta);
  const auto file = ::gpilqg::test::temporary_dir("exact_known_noise") / "gp.h5";
  save_fitted_gp(file, "/gp", *model);
  const auto loaded = load_fitted_gp(file, "/gp", backend);
  EXPECT_EQ(loaded->training_set().noise_variance, known.noise_variance);
  EXPECT_DOUBLE_EQ(loaded->negative_log_marginal_likelihood(), model->negative_log_marginal_likelihood());
}

TEST(DenseCholesky, InverseFromFactorEqualsEigensInverse) {
  for (int threads : {1, 2}) {
    for (int n : {1, 7, 48, 49, 130, 301, 777}) {
      const Matrix a = Matrix::Random(n, n);
      const Matrix spd = a * a.transpose() + n * Matrix::Identity(n, n);
      Matrix factor;
      const auto outcome = detail::cholesky_with_jitter(spd, 0.0, JitterSchedule{}, factor, threads);
      ASSERT_EQ(outcome.status, FactorStatus::Ok);
      const Matrix l = factor.triangularView<Eigen::Lower>();
      EXPECT_TRUE(matrices_near(l * l.transpose(), spd, 1e-10 * n)) << "n = " << n << ", threads " << threads;
      detail::inverse_from_cholesky(factor, threads);
      detail::symmetrize_from_lower(factor);
      EXPECT_TRUE(matrices_near(factor, spd.inverse(), 1e-12 / n, 1e-9)) << "n = " << n << ", threads " << threads;
    }
  }
  Matrix not_positive = -Matrix::Identity(500, 500);
  EXPECT_FALSE(detail::cholesky_in_place(not_positive, 2));
}

TEST(ExactGp, TwoThreadsGiveTheSameNlmlAndGradient) {
  const TrainingSet data = smooth_data(500, 4);
  FitOptions options;
  auto one = ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints, 1}).objective(data, options);
  auto two = ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints, 2}).objective(data, options);
  Vector theta(4), g1, g2;
  theta << -0.5, 0.2, 0.1, std::log(0.05);
  const double v1 = one->evaluate(theta, &g1).value, v2 = two->evaluate(theta, &g2).value;
  EXPECT_NEAR(v1, v2, 1e-9 * std::abs(v1));
  EXPECT_TRUE(matrices_near(g1, g2, 1e-9, 1e-9));
}

}  // namespace
}  // namespace gpilqg::gp::test
