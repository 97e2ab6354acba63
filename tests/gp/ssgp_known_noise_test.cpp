// Sparse spectrum GP with a noise variance known per training point (TrainingSet::noise_variance):
// y ~ N(0, (sf2/m) Phi Phi' + diag(sn2 + v_i)). Checked against
//  1. a dense implementation of that Gaussian written here (NLML, posterior mean and latent variance);
//  2. central differences of the NLML for every parameter, and of the predictions for the input;
//  3. the identities v_i = c <=> sn'^2 = sn^2 + c, and v_i = 0 <=> no known noise;
//  4. moment matching of the conditioned models (point input, Monte Carlo);
//  5. the backend end to end: subsets, a fit, a saved and reloaded model.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "gp_test_support.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "moment_matching_checks.hpp"

namespace gpilqg::gp::test {
namespace {

constexpr int kN = 40, kD = 3, kM = 10;
constexpr double kLog2Pi = 1.8378770664093454836;

/// N points uniform in [-2, 2]^D, smooth targets with noise, and known variances uniform in [lo, hi].
TrainingSet known_noise_data(int n, unsigned seed, double lo = 0.01, double hi = 0.2) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> box(-2.0, 2.0), variance(lo, hi);
  std::normal_distribution<double> normal(0.0, 1.0);
  TrainingSet data{Matrix(n, kD), Vector(n), Vector(n)};
  for (Eigen::Index i = 0; i < data.inputs.size(); ++i) data.inputs.data()[i] = box(rng);
  for (int i = 0; i < n; ++i) {
    data.noise_variance(i) = variance(rng);
    data.targets(i) = std::sin(data.inputs(i, 0)) + 0.5 * data.inputs(i, 1) * std::cos(data.inputs(i, 2)) +
                      std::sqrt(data.noise_variance(i) + 0.01) * normal(rng);
  }
  return data;
}

/// Random parameters: log l in log [0.6, 1.8], sf in [0.7, 1.5], sn in [0.05, 0.3], W ~ N(0, I).
Vector random_theta(unsigned seed, int m = kM) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Vector hyper(kD + 2);
  for (int d = 0; d < kD; ++d) hyper(d) = std::log(0.6 + 1.2 * unit(rng));
  hyper(kD) = std::log(0.7 + 0.8 * unit(rng));
  hyper(kD + 1) = std::log(0.05 + 0.25 * unit(rng));
  Matrix W(m, kD);
  for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = normal(rng);
  return SsgpLayout{kD, m}.pack(hyper, W);
}

// ---------------------------------------------------------------------------------------------------
// The dense reference, from the model's definition alone.

/// The SSGP model at theta in function space: C = (sf2/m) Phi Phi' + diag(sn2 + v_i).
struct DenseModel {
  Matrix S;       ///< m x D frequencies W ./ l'
  double prior;   ///< sf2 / m
  Matrix Phi;     ///< N x 2m, [cos(X S'), sin(X S')]
  Vector r;       ///< targets
  Eigen::LLT<Matrix> C;
  Vector Cinv_r;

  DenseModel(const TrainingSet& data, const Vector& theta) {
    const SsgpLayout layout = SsgpLayout::from_size(static_cast<int>(theta.size()), kD);
    const Vector ell = theta.head(kD).array().exp();
    S = layout.spectral_points(theta) * ell.cwiseInverse().asDiagonal();
    prior = std::exp(2.0 * theta(kD)) / layout.frequencies;
    Phi = features(data.inputs);
    Vector noise = Vector::Constant(data.size(), std::exp(2.0 * theta(kD + 1)));
    if (data.noise_variance.size() > 0) noise += data.noise_variance;
    Matrix K = prior * Phi * Phi.transpose();
    K.diagonal() += noise;
    C.compute(K);
    r = data.targets;
    Cinv_r = C.solve(r);
  }

  Matrix features(const Matrix& X) const {
    const Matrix Z = X * S.transpose();
    Matrix F(X.rows(), 2 * S.rows());
    F << Z.array().cos().matrix(), Z.array().sin().matrix();
    return F;
  }

  double nlml() const {
    const Matrix L = C.matrixL();
    return 0.5 * r.dot(Cinv_r) + L.diagonal().array().log().sum() + 0.5 * static_cast<double>(r.size()) * kLog2Pi;
  }

  /// Posterior mean k*'C^-1 r and latent variance (sf2/m) phi*'phi* - k*'C^-1 k*, k* = (sf2/m) Phi phi*.
  void predict(const Vector& x, double& mean, double& variance) const {
    const Vector phi = features(x.transpose()).row(0).transpose();
    const Vector k = prior * Phi * phi;
    mean = k.dot(Cinv_r);
    variance = prior * phi.squaredNorm() - k.dot(C.solve(k));
  }
};

double relative_difference(double a, double b) { return std::abs(a - b) / std::abs(b); }

// ---------------------------------------------------------------------------------------------------
// The likelihood

TEST(SsgpKnownNoise, NlmlMatchesTheDenseGaussianOfTheWeightedModel) {
  const TrainingSet data = known_noise_data(kN, 1);
  const SsgpLikelihood lik(data.inputs, data.targets, kM, {}, 1, data.noise_variance);
  for (unsigned seed : {11u, 12u, 13u, 14u}) {
    const Vector theta = random_theta(seed);
    const NlmlEvaluation e = lik.evaluate(theta);
    ASSERT_EQ(e.status, FactorStatus::Ok);
    const double dense = DenseModel(data, theta).nlml();
    EXPECT_LT(relative_difference(e.value, dense), 1e-9) << "seed " << seed << ": " << e.value << " vs " << dense;
  }
  // The known noise counts: the likelihood without it is another number.
  const Vector theta = random_theta(11);
  const double without = SsgpLikelihood(data.inputs, data.targets, kM).evaluate(theta).value;
  EXPECT_GT(std::abs(without - lik.evaluate(theta).value), 1.0);
}

TEST(SsgpKnownNoise, EveryGradientEntryMatchesCentralDifferences) {
  const TrainingSet data = known_noise_data(kN, 2);
  const SsgpLikelihood lik(data.inputs, data.targets, kM, {}, 1, data.noise_variance);
  for (unsigned seed : {21u, 22u}) {
    const Vector theta = random_theta(seed);
    Vector grad;
    ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
    EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta))) << "seed " << seed;
  }
}

TEST(SsgpKnownNoise, GradientMatchesWhenKnownNoiseRangesFromNoneToDominant) {
  // v_i from 0 to 2 against sn = 0.05: u_i = sn2 / (sn2 + v_i) from 1 down to ~1e-3, so the terms
  // u_i (1 - u_i) (e_i^2/sn2 + h_i) of the noise gradient are far from zero and far from uniform.
  TrainingSet data = known_noise_data(kN, 3, 0.0, 2.0);
  for (int i = 0; i < kN; i += 5) data.noise_variance(i) = 0.0;
  const SsgpLikelihood lik(data.inputs, data.targets, kM, {}, 1, data.noise_variance);
  Vector theta = random_theta(31);
  theta(kD + 1) = std::log(0.05);
  Vector grad;
  ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
  EXPECT_LT(relative_difference(lik.evaluate(theta).value, DenseModel(data, theta).nlml()), 1e-9);
  EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta)));
  EXPECT_GT(std::abs(grad(kD + 1)), 0.1);  // a noise gradient that can tell
}

TEST(SsgpKnownNoise, TwoThreadsGiveTheSameValueAndGradient) {
  const int n = 1300;  // >= 500 points per thread, so two blocks are used
  const TrainingSet data = known_noise_data(n, 4);
  const Vector theta = random_theta(41, 20);
  const SsgpLikelihood one(data.inputs, data.targets, 20, {}, 1, data.noise_variance);
  const SsgpLikelihood two(data.inputs, data.targets, 20, {}, 2, data.noise_variance);
  Vector g1, g2;
  const double v1 = one.evaluate(theta, &g1).value;
  const double v2 = two.evaluate(theta, &g2).value;
  EXPECT_NEAR(v1, v2, 1e-12 * std::abs(v1));
  EXPECT_TRUE(matrices_near(g2, g1, 1e-11 * g1.cwiseAbs().maxCoeff()));
}

TEST(SsgpKnownNoise, AConstantKnownNoiseIsAHomoscedasticNoiseOfTheSum) {
  // v_i = c with sn is sn'^2 = sn^2 + c without known noise: the same NLML, the same gradient in
  // l, sf and W, a noise gradient in the ratio sn^2 / sn'^2, and the same posterior.
  TrainingSet known = known_noise_data(kN, 5);
  const double c = 0.04, sn = 0.12;
  known.noise_variance.setConstant(c);
  const TrainingSet plain{known.inputs, known.targets};
  Vector theta = random_theta(51);
  theta(kD + 1) = std::log(sn);
  Vector theta_sum = theta;
  theta_sum(kD + 1) = 0.5 * std::log(sn * sn + c);
  const SsgpLikelihood lik_known(known.inputs, known.targets, kM, {}, 1, known.noise_variance);
  const SsgpLikelihood lik_plain(plain.inputs, plain.targets, kM);
  Vector g_known, g_sum;
  const double nlml_known = lik_known.evaluate(theta, &g_known).value;
  const double nlml_sum = lik_plain.evaluate(theta_sum, &g_sum).value;
  EXPECT_LT(relative_difference(nlml_known, nlml_sum), 1e-12);
  const double scale = g_sum.cwiseAbs().maxCoeff();
  Vector expected = g_sum;
  expected(kD + 1) *= sn * sn / (sn * sn + c);
  EXPECT_TRUE(matrices_near(g_known, expected, 1e-10 * scale, 1e-9));
  EXPECT_GT(std::abs(g_sum(kD + 1)), 0.1);

  const SsgpPredictor p_known = lik_known.predictor(theta);
  const SsgpPredictor p_sum = lik_plain.predictor(theta_sum);
  EXPECT_TRUE(near_relative(p_known.alpha(), p_sum.alpha(), 1e-10));
  EXPECT_TRUE(near_relative(p_known.variance_matrix(), p_sum.variance_matrix(), 1e-10));
}

TEST(SsgpKnownNoise, ZeroKnownNoiseIsNoKnownNoise) {
  // v = 0 takes the weighted arithmetic (U = I) and must give the unweighted path's numbers.
  TrainingSet data = known_noise_data(kN, 6);
  const Vector zeros = Vector::Zero(kN);
  for (unsigned seed : {61u, 62u}) {
    const Vector theta = random_theta(seed);
    Vector g_zero, g_none;
    const double zero = SsgpLikelihood(data.inputs, data.targets, kM, {}, 1, zeros).evaluate(theta, &g_zero).value;
    const double none = SsgpLikelihood(data.inputs, data.targets, kM).evaluate(theta, &g_none).value;
    EXPECT_LT(relative_difference(zero, none), 1e-12) << "seed " << seed;
    EXPECT_TRUE(matrices_near(g_zero, g_none, 1e-12 * g_none.cwiseAbs().maxCoeff(), 1e-12)) << "seed " << seed;
  }
}

TEST(SsgpKnownNoise, WrongKnownNoiseIsRefused) {
  const TrainingSet data = known_noise_data(kN, 7);
  EXPECT_THROW(SsgpLikelihood(data.inputs, data.targets, kM, {}, 1, data.noise_variance.head(5)),
               std::invalid_argument);
  Vector negative = data.noise_variance;
  negative(3) = -0.1;
  EXPECT_THROW(SsgpLikelihood(data.inputs, data.targets, kM, {}, 1, negative), std::invalid_argument);
  Vector nan = data.noise_variance;
  nan(4) = std::nan("");
  EXPECT_THROW(SsgpLikelihood(data.inputs, data.targets, kM, {}, 1, nan), std::invalid_argument);
  TrainingSet bad = data;
  bad.noise_variance(2) = -1.0;
  EXPECT_THROW(SsgpBackend().objective(bad, FitOptions{}), std::invalid_argument);
  EXPECT_THROW(SsgpBackend().condition(bad, random_theta(71)), std::invalid_argument);
}

TEST(SsgpKnownNoise, NonFiniteParametersAreAFailedEvaluationNotNaN) {
  const TrainingSet data = known_noise_data(kN, 8);
  const SsgpLikelihood lik(data.inputs, data.targets, kM, {}, 1, data.noise_variance);
  Vector theta = random_theta(81);
  theta(kD + 1) = 800.0;  // sn2 = exp(1600) overflows
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(theta, &grad);
  EXPECT_EQ(e.status, FactorStatus::Failed);
  EXPECT_TRUE(std::isinf(e.value));
  EXPECT_TRUE(grad.allFinite());
  // sn2 = exp(-600): u_i ~ 1e-259, A of the same order; a finite result or a failed one, never NaN.
  theta(kD + 1) = -300.0;
  const NlmlEvaluation tiny = lik.evaluate(theta, &grad);
  EXPECT_FALSE(std::isnan(tiny.value));
  EXPECT_TRUE(grad.allFinite());
}

// ---------------------------------------------------------------------------------------------------
// The conditioned model

TEST(SsgpKnownNoise, PredictionsAreTheDensePosteriorOfTheWeightedModel) {
  const TrainingSet data = known_noise_data(kN, 9);
  const Vector theta = random_theta(91);
  const auto model = SsgpBackend().condition(data, theta);
  EXPECT_EQ(model->conditioning().status, FactorStatus::Ok);
  const DenseModel dense(data, theta);
  EXPECT_LT(relative_difference(model->negative_log_marginal_likelihood(), dense.nlml()), 1e-9);

  const Matrix tests = ::gpilqg::test::random_vector(6 * kD, -2.5, 2.5, 92).reshaped(6, kD);
  Prediction p;
  for (Eigen::Index i = 0; i < tests.rows(); ++i) {
    const Vector z = tests.row(i).transpose();
    model->predict(z, p, PredictionRequest{true, true});
    double mean = 0, variance = 0;
    dense.predict(z, mean, variance);
    EXPECT_NEAR(p.mean, mean, 1e-8 * (1.0 + std::abs(mean))) << "point " << i;
    EXPECT_NEAR(p.variance, variance, 1e-8 * (1.0 + std::abs(variance))) << "point " << i;
    EXPECT_GT(variance, 1e-4) << "point " << i;  // a variance that can tell

    const Matrix numeric = ::gpilqg::test::numeric_jacobian(
        [&](const Vector& at) {
          Prediction q;
          model->predict(at, q, PredictionRequest{true, false});
          return Vector((Vector(2) << q.mean, q.variance).finished());
        },
        z, 1e-6);
    EXPECT_TRUE(matrices_near(p.mean_gradient.transpose(), numeric.row(0), 1e-8, 1e-6)) << "point " << i;
    EXPECT_TRUE(matrices_near(p.variance_gradient.transpose(), numeric.row(1), 1e-8, 1e-6)) << "point " << i;
  }
}

TEST(SsgpKnownNoise, MomentMatchingAtAPointInputIsThePredictionAndAgreesWithMonteCarlo) {
  // Moment matching reads the posterior's alpha and C only; with known noise they are the weighted
  // model's, so the moments are those of the weighted model's predictions.
  std::vector<std::unique_ptr<FittedGp>> models;
  for (unsigned a = 0; a < 2; ++a) {
    const TrainingSet data = known_noise_data(kN + 20, 100 + a, 0.0, 0.5);
    models.push_back(SsgpBackend().condition(data, random_theta(110 + a, a == 0 ? kM : 7)));
  }
  const FittedOutputs fits(std::move(models));
  expect_point_input_is_the_prediction(fits, "SSGP known noise");
  Vector mu(kD);
  mu << 0.2, -0.3, 0.1;
  check_against_monte_carlo(*fits.matcher, fits.posterior(), mu, make_sigma(kD, 0.45, 7), 100000,
                            "SSGP known noise");
  check_derivatives(*fits.matcher, mu, make_sigma(kD, 0.4, 3), "SSGP known noise");
}

// ---------------------------------------------------------------------------------------------------
// The backend end to end

TEST(SsgpKnownNoise, SubsetsFitsAndSavedModelsKeepTheKnownNoise) {
  const TrainingSet data = known_noise_data(kN, 10);
  const TrainingSet some = data.subset({5, 17, 32});
  ASSERT_EQ(some.noise_variance.size(), 3);
  EXPECT_EQ(some.noise_variance(1), data.noise_variance(17));

  SsgpOptions options;
  options.frequencies = kM;
  const SsgpBackend backend(options);
  EXPECT_TRUE(backend.takes_known_noise());
  const std::vector<std::string> taking = backends_taking_known_noise();
  EXPECT_NE(std::find(taking.begin(), taking.end(), "ssgp"), taking.end());
  FitOptions fit;
  fit.restarts = 0;
  fit.max_evaluations = 80;
  const FitResult result = backend.fit(data, fit);
  ASSERT_NE(result.model, nullptr);
  EXPECT_EQ(result.model->training_set().noise_variance, data.noise_variance);
  const Vector& theta = result.model->parameters();
  const SsgpLikelihood lik(data.inputs, data.targets, kM, {}, 1, data.noise_variance);
  EXPECT_NEAR(result.model->negative_log_marginal_likelihood(), lik.evaluate(theta).value, 1e-9);
  EXPECT_LT(relative_difference(result.model->negative_log_marginal_likelihood(), DenseModel(data, theta).nlml()),
            1e-9);

  const auto file = ::gpilqg::test::temporary_dir("ssgp_known_noise") / "gp.h5";
  save_fitted_gp(file, "/gp", *result.model);
  const auto loaded = load_fitted_gp(file, "/gp", backend);
  EXPECT_EQ(loaded->backend_name(), "ssgp");
  EXPECT_EQ(loaded->training_set().noise_variance, data.noise_variance);
  EXPECT_DOUBLE_EQ(loaded->negative_log_marginal_likelihood(), result.model->negative_log_marginal_likelihood());
  Prediction a, b;
  const Vector z = Vector::Constant(kD, 0.3);
  result.model->predict(z, a);
  loaded->predict(z, b);
  EXPECT_DOUBLE_EQ(a.mean, b.mean);
  EXPECT_DOUBLE_EQ(a.variance, b.variance);
}

TEST(SsgpKnownNoise, AFitWithKnownNoiseLearnsOnlyTheRest) {
  // Targets with noise variance v_i + 0.05^2, v_i up to 0.25: a fit told v learns a homoscedastic
  // part well below the one a fit without v needs to explain the same scatter.
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> box(-2.0, 2.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 200;
  TrainingSet data{Matrix(n, kD), Vector(n), Vector::LinSpaced(n, 0.0, 0.25)};
  for (Eigen::Index i = 0; i < data.inputs.size(); ++i) data.inputs.data()[i] = box(rng);
  for (int i = 0; i < n; ++i)
    data.targets(i) = std::sin(data.inputs(i, 0)) + std::sqrt(data.noise_variance(i) + 0.05 * 0.05) * normal(rng);
  SsgpOptions options;
  options.frequencies = kM;
  const SsgpBackend backend(options);
  FitOptions fit;
  fit.restarts = 0;
  fit.max_evaluations = 150;
  const auto with_known = backend.fit(data, fit).model;
  const auto without = backend.fit(TrainingSet{data.inputs, data.targets}, fit).model;
  const double sn_known = std::exp(with_known->parameters()(kD + 1));
  const double sn_plain = std::exp(without->parameters()(kD + 1));
  EXPECT_LT(sn_known, 0.5 * sn_plain) << "sn with known noise " << sn_known << ", without " << sn_plain;
}

}  // namespace
}  // namespace gpilqg::gp::test
