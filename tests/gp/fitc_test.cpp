// FITC / SPGP: agreement with the gp_oracle golden numbers (GPML 4.2 infFITC and NumPy, both jitter
// rules, the pseudo-input gradient), central differences for every analytic gradient, the reduction
// to the exact GP when the pseudo-inputs sit on the training inputs, the initialisation of the
// pseudo-inputs, the backend (fit, options, prediction API) and failure paths. The properties shared
// with every backend (save/load, degenerate data, far-field prior, ...) are in backend_typed_test.cpp.

#include "gpilqg/gp/fitc.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <limits>
#include <atomic>
#include <random>
#include <thread>
#include <tuple>
#include <set>

#include "gp_test_support.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::gp::test {
namespace {

Matrix oracle_inducing() { return read_numeric_csv(oracle_dir() / "data" / "Xu.csv"); }

Vector fitc_oracle_theta(const OracleData& o) { return FitcLayout{3, 7}.pack(o.hyp.pack(), oracle_inducing()); }

/// Predictions of a predictor with the oracle's prior mean m(x) = sum sin(x_d) added.
Predictions predict_with_prior_mean(const FitcPredictor& p, const Matrix& Xs) {
  const int D = p.input_dim(), M = p.inducing();
  Predictions out{Vector(Xs.rows()), Vector(Xs.rows()), Matrix(Xs.rows(), D), Matrix(Xs.rows(), D)};
  Vector k(M), c(M), xs(D), dm(D), dv(D), dprior(D);
  for (Eigen::Index i = 0; i < Xs.rows(); ++i) {
    const Vector x = Xs.row(i).transpose();
    double mean = 0, var = 0;
    p.predict(x, k.data(), c.data(), xs.data(), mean, &var, dm.data(), dv.data());
    out.mean(i) = mean + sum_of_sines(x, &dprior);
    out.variance(i) = var;
    out.dmean.row(i) = (dm + dprior).transpose();
    out.dvariance.row(i) = dv.transpose();
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------
// Oracle agreement (values to 1e-10 relative, prediction gradients to 1e-9)

TEST(FitcOracle, DefaultJitterMatchesGpmlAndNumpy) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("gpml")["fitc_default"];
  const auto numpy = load_oracle_json("python")["numpy_fitc_default"];
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7, FitcJitter::gpml());
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(fitc_oracle_theta(o), &grad);
  EXPECT_EQ(e.status, FactorStatus::Ok);
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(ref["nlZ"].get<double>()), 1e-10));
  Vector dhyp(5);
  dhyp << json_matrix(ref["dnlZ_cov"]), ref["dnlZ_lik"].get<double>();
  EXPECT_TRUE(near_relative(grad.head(5), dhyp, 1e-10));

  const Predictions p = predict_with_prior_mean(lik.predictor(fitc_oracle_theta(o)), o.test_inputs);
  EXPECT_TRUE(near_relative(p.mean, json_matrix(ref["fmu"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(ref["fs2"]), 1e-10));
  EXPECT_TRUE(near_relative(p.mean, json_matrix(numpy["fmu"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(numpy["fs2"]), 1e-10));
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(numpy["dfmu_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(numpy["dfs2_dxs"]), 1e-9, 1e-9));
  // GPML's central differences (h = 1e-5) carry about 1e-9 of truncation error.
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(ref["dfmu_dxs_fd"]), 1e-8, 1e-8));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(ref["dfs2_dxs_fd"]), 1e-8, 1e-8));
}

TEST(FitcOracle, PseudoInputGradientMatchesGpml) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("gpml")["fitc_xu"];
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7, FitcJitter::gpml());
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(fitc_oracle_theta(o), &grad);
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(ref["nlZ"].get<double>()), 1e-10));
  Vector dhyp(5);
  dhyp << json_matrix(ref["dnlZ_cov"]), ref["dnlZ_lik"].get<double>();
  EXPECT_TRUE(near_relative(grad.head(5), dhyp, 1e-10));
  const Matrix dxu = grad.tail(21).reshaped(7, 3);  // column-major, as vec(Xu)
  EXPECT_TRUE(near_relative(dxu, json_matrix(ref["dnlZ_xu"]), 1e-10));
}

TEST(FitcOracle, FixedJitterMatchesGpmlAndNumpy) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("gpml")["fitc_snu1e-5"];
  const auto numpy = load_oracle_json("python")["numpy_fitc_snu2_1e-10"];
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7, FitcJitter::fixed(1e-10));
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(fitc_oracle_theta(o), &grad);
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(ref["nlZ"].get<double>()), 1e-10));
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(numpy["nlZ"].get<double>()), 1e-10));
  Vector dhyp(5);
  dhyp << json_matrix(ref["dnlZ_cov"]), ref["dnlZ_lik"].get<double>();
  EXPECT_TRUE(near_relative(grad.head(5), dhyp, 1e-10));
  const Predictions p = predict_with_prior_mean(lik.predictor(fitc_oracle_theta(o)), o.test_inputs);
  EXPECT_TRUE(near_relative(p.mean, json_matrix(ref["fmu"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(ref["fs2"]), 1e-10));
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(numpy["dfmu_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(numpy["dfs2_dxs"]), 1e-9, 1e-9));
}

TEST(FitcOracle, TheJitterRuleMatters) {
  // The two rules differ by 2.8e-5 in nlZ (README): GPML's relative rule is really applied.
  const OracleData o = load_oracle();
  const auto run = [&](FitcJitter j) {
    return FitcLikelihood(o.train.inputs, o.train.targets, 7, j).evaluate(fitc_oracle_theta(o)).value;
  };
  EXPECT_NEAR(run(FitcJitter::fixed(1e-10)) - run(FitcJitter::gpml()), 2.8283178266974573e-05, 1e-9);
}

TEST(FitcOracle, TheBackendPredictsTheOracleThroughTheInterface) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("gpml")["fitc_default"];
  const auto numpy = load_oracle_json("python")["numpy_fitc_default"];
  const auto model = FitcBackend().condition(o.train, fitc_oracle_theta(o));
  EXPECT_EQ(model->backend_name(), "fitc");
  EXPECT_EQ(model->conditioning().status, FactorStatus::Ok);
  EXPECT_TRUE(near_relative(scalar(model->negative_log_marginal_likelihood()),
                            scalar(ref["nlZ"].get<double>()), 1e-10));
  Prediction p;
  const Matrix dmean_ref = json_matrix(numpy["dfmu_dxs"]);
  for (Eigen::Index i = 0; i < o.test_inputs.rows(); ++i) {
    const Vector z = o.test_inputs.row(i).transpose();
    model->predict(z, p, PredictionRequest{true, true});
    add_prior_mean(&sum_of_sines, z, p);
    EXPECT_TRUE(near_relative(scalar(p.mean), scalar(json_matrix(ref["fmu"])(i)), 1e-10));
    EXPECT_TRUE(near_relative(scalar(p.variance), scalar(json_matrix(ref["fs2"])(i)), 1e-10));
    EXPECT_TRUE(matrices_near(p.mean_gradient.transpose(), dmean_ref.row(i), 1e-9, 1e-9));
    EXPECT_TRUE(
        matrices_near(p.variance_gradient.transpose(), json_matrix(numpy["dfs2_dxs"]).row(i), 1e-9, 1e-9));
  }
}

// ---------------------------------------------------------------------------------------------------
// Central differences for every analytic gradient

TEST(FitcGradient, EveryParameterMatchesCentralDifferencesForBothJitterRules) {
  const OracleData o = load_oracle();
  Vector theta = fitc_oracle_theta(o);
  theta.head(5) += Vector::LinSpaced(5, -0.4, 0.3);                     // away from the reference values
  theta.tail(21) += 0.3 * ::gpilqg::test::random_vector(21, -1, 1, 5);  // and other pseudo-inputs
  for (const FitcJitter& rule :
       {FitcJitter::gpml(), FitcJitter::fixed(1e-10), FitcJitter{FitcJitterKind::Relative, 1e-3}}) {
    const FitcLikelihood lik(o.train.inputs, o.train.targets, 7, rule);
    Vector grad;
    ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
    EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta))) << "jitter value " << rule.value;
  }
}

TEST(FitcGradient, MatchesCentralDifferencesInFiveDimensionsWithManyPoints) {
  const int N = 60, D = 5, M = 12;
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.array().sin().rowwise().sum().matrix() + 0.1 * Vector::Random(N);
  Vector hyper(D + 2);
  hyper << 0.2, 0.5, -0.1, 0.8, 0.3, 0.1, std::log(0.2);
  const Matrix Xu = 2.0 * Matrix::Random(M, D);
  const FitcLikelihood lik(X, r, M);
  const Vector theta = FitcLayout{D, M}.pack(hyper, Xu);
  Vector grad;
  ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
  EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta)));
}

TEST(FitcGradient, StaysExactWhenTheJitterIsEscalated) {
  // Two identical pseudo-inputs and no jitter of its own: Kuu is singular, the schedule adds jitter
  // proportional to sf2, and the gradient accounts for it.
  const OracleData o = load_oracle();
  Matrix Xu = oracle_inducing();
  Xu.row(1) = Xu.row(0);
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7, FitcJitter::fixed(0.0));
  Vector theta = FitcLayout{3, 7}.pack(o.hyp.pack(), Xu);
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(theta, &grad);
  ASSERT_EQ(e.status, FactorStatus::JitterAdded);
  EXPECT_GT(e.jitter, 0.0);
  // Differences in the hyperparameters only: moving one of the duplicated points would change
  // which jitter the schedule needs.
  const Vector numeric = numeric_gradient(lik, theta);
  EXPECT_TRUE(gradient_near(grad.head(5), numeric.head(5)));
}

TEST(FitcGradient, TwoThreadsGiveTheSameValueAndGradient) {
  const int N = 1300, D = 3, M = 25;  // >= 500 points per thread, so two blocks are used
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.array().sin().rowwise().sum().matrix() + 0.1 * Vector::Random(N);
  Vector hyper(D + 2);
  hyper << 0.1, -0.2, 0.3, 0.2, std::log(0.1);
  const Vector theta = FitcLayout{D, M}.pack(hyper, 2.0 * Matrix::Random(M, D));
  Vector g1, g2;
  const double v1 = FitcLikelihood(X, r, M, FitcJitter::gpml(), {}, 1).evaluate(theta, &g1).value;
  const double v2 = FitcLikelihood(X, r, M, FitcJitter::gpml(), {}, 2).evaluate(theta, &g2).value;
  EXPECT_NEAR(v1, v2, 1e-12 * std::abs(v1));
  EXPECT_TRUE(matrices_near(g2, g1, 1e-11 * g1.cwiseAbs().maxCoeff()));
}

TEST(FitcGradient, PredictionGradientsMatchCentralDifferencesFarAndNear) {
  const OracleData o = load_oracle();
  const FitcPredictor p = FitcLikelihood(o.train.inputs, o.train.targets, 7).predictor(fitc_oracle_theta(o));
  Vector k(7), c(7), xs(3), dm(3), dv(3);
  for (const Vector& x : {Vector(o.test_inputs.row(2).transpose()),
                          Vector(oracle_inducing().row(3).transpose()), Vector(Vector::Constant(3, 2.5))}) {
    double mean = 0, var = 0;
    p.predict(x, k.data(), c.data(), xs.data(), mean, &var, dm.data(), dv.data());
    const Matrix numeric = ::gpilqg::test::numeric_jacobian(
        [&](const Vector& at) {
          Vector v(2);
          p.predict(at, k.data(), c.data(), xs.data(), v(0), &v(1));
          return v;
        },
        x, 1e-6);
    EXPECT_TRUE(matrices_near(dm.transpose(), numeric.row(0), 1e-8, 1e-6));
    EXPECT_TRUE(matrices_near(dv.transpose(), numeric.row(1), 1e-8, 1e-6));
  }
}

// ---------------------------------------------------------------------------------------------------
// Reduction: pseudo-inputs on the training inputs give the exact GP

/// `fitc` (pseudo-inputs at the training inputs) against the exact GP on `data` at `hyper`: the NLML,
/// and mean, variance and their input gradients at random points.
void expect_the_exact_gp(const FittedGp& fitc, const TrainingSet& data, const Vector& hyper) {
  const auto reference = ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints}).condition(data, hyper);
  EXPECT_NEAR(fitc.negative_log_marginal_likelihood(), reference->negative_log_marginal_likelihood(),
              1e-6 * std::abs(reference->negative_log_marginal_likelihood()));
  Prediction a, b;
  for (int i = 0; i < 10; ++i) {
    const Vector z = 3.5 * Vector::Random(data.input_dim());
    fitc.predict(z, a, PredictionRequest{true, true});
    reference->predict(z, b, PredictionRequest{true, true});
    EXPECT_NEAR(a.mean, b.mean, 1e-6);
    EXPECT_NEAR(a.variance, b.variance, 1e-6);
    EXPECT_TRUE(matrices_near(a.mean_gradient, b.mean_gradient, 1e-5));
    EXPECT_TRUE(matrices_near(a.variance_gradient, b.variance_gradient, 1e-5));
  }
}

TEST(FitcReduction, PseudoInputsAtTheTrainingInputsGiveTheExactGp) {
  // With Xu = X, Qff = Kff Kuu^-1 Kff = Kff - snu2 I + O(snu2^2) and Lambda = (snu2 + sn2) I, so
  // Qff + Lambda = Kff + sn2 I up to snu2^2 / lambda_min(Kff): FITC equals the exact GP.
  const OracleData o = load_oracle();
  const auto exact = load_oracle_json("gpml")["exact"];
  const Vector theta = FitcLayout{3, 20}.pack(o.hyp.pack(), o.train.inputs);
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 20, FitcJitter::fixed(1e-10));
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(theta, &grad);
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(exact["nlZ"].get<double>()), 1e-7));
  Vector dhyp(5);
  dhyp << json_matrix(exact["dnlZ_cov"]), exact["dnlZ_lik"].get<double>();
  EXPECT_TRUE(near_relative(grad.head(5), dhyp, 1e-6));
  const Predictions p = predict_with_prior_mean(lik.predictor(theta), o.test_inputs);
  EXPECT_TRUE(near_relative(p.mean, json_matrix(exact["fmu"]), 1e-7));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(exact["fs2"]), 1e-6));
  const auto numpy = load_oracle_json("python")["numpy_exact"];
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(numpy["dfmu_dxs"]), 1e-6, 1e-6));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(numpy["dfs2_dxs"]), 1e-6, 1e-6));

  // The same through the interface against the exact backend, on larger data at other points.
  const int N = 80, D = 2;
  TrainingSet data{3.0 * Matrix::Random(N, D), Vector(N)};
  data.targets = data.inputs.col(0).array().sin() * data.inputs.col(1).array().cos();
  Vector hyper(D + 2);
  hyper << std::log(1.2), std::log(0.9), std::log(0.8), std::log(0.1);
  FitcOptions options;
  options.jitter = FitcJitter::fixed(1e-10);
  const auto fitc = FitcBackend(options).condition(data, FitcLayout{D, N}.pack(hyper, data.inputs));
  expect_the_exact_gp(*fitc, data, hyper);
}

// ---------------------------------------------------------------------------------------------------
// A noise variance known per point: Lambda = diag(max(Kff - Qff, 0)) + sn2 I + diag(v)

/// FITC's nlZ written densely: C = Qff + Lambda, 0.5 r'C^-1 r + 0.5 log|C| + N/2 log(2 pi).
double dense_fitc_nlml(const Matrix& X, const Vector& r, const Vector& theta, int M, double snu2, const Vector& v) {
  const int D = static_cast<int>(X.cols());
  const FitcLayout layout{D, M};
  const Vector ell = theta.head(D).array().exp();
  const double sf2 = std::exp(2.0 * theta(D)), sn2 = std::exp(2.0 * theta(D + 1));
  const Matrix Xu = layout.inducing_inputs(theta);
  const auto k = [&](const Matrix& A, const Matrix& B) {
    Matrix K(A.rows(), B.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      for (Eigen::Index j = 0; j < B.rows(); ++j)
        K(i, j) = sf2 * std::exp(-0.5 * ((A.row(i) - B.row(j)).transpose().cwiseQuotient(ell)).squaredNorm());
    return K;
  };
  const Matrix Kuu = k(Xu, Xu) + snu2 * Matrix::Identity(M, M);
  const Matrix Kuf = k(Xu, X);
  const Matrix Qff = Kuf.transpose() * Kuu.llt().solve(Kuf);
  const Vector lambda = (sf2 - Qff.diagonal().array()).max(0.0) + sn2 + v.array();
  const Matrix C = Qff + Matrix(lambda.asDiagonal());
  const Eigen::LLT<Matrix> llt(C);
  const Matrix L = llt.matrixL();
  return 0.5 * r.dot(llt.solve(r)) + L.diagonal().array().log().sum() + 0.5 * X.rows() * std::log(2.0 * M_PI);
}

TEST(FitcKnownNoise, TheNlmlAndItsGradientMatchADenseFitcAndCentralDifferences) {
  const int N = 50, D = 3, M = 9;
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.array().sin().rowwise().sum().matrix() + 0.1 * Vector::Random(N);
  const Vector v = (0.1 * (Vector::Random(N).array() + 1.05)).matrix();  // in [0.005, 0.205]
  Vector hyper(D + 2);
  hyper << 0.2, -0.1, 0.4, 0.1, std::log(0.05);
  const Vector theta = FitcLayout{D, M}.pack(hyper, 2.0 * Matrix::Random(M, D));
  const FitcLikelihood lik(X, r, M, FitcJitter::fixed(1e-8), {}, 1, v);
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(theta, &grad);
  ASSERT_EQ(e.status, FactorStatus::Ok);
  EXPECT_NEAR(e.value, dense_fitc_nlml(X, r, theta, M, 1e-8, v), 1e-9 * std::abs(e.value));
  EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta)));
  // The known noise matters: without it the value differs.
  EXPECT_GT(std::abs(FitcLikelihood(X, r, M, FitcJitter::fixed(1e-8)).evaluate(theta).value - e.value), 1.0);
}

TEST(FitcKnownNoise, AConstantKnownNoiseIsTheSameAsALargerLearnedOne) {
  const int N = 40, D = 2, M = 8;
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.col(0).array().sin().matrix() + 0.1 * Vector::Random(N);
  const double sn2 = 0.01, c = 0.03;
  Vector hyper(D + 2);
  hyper << 0.1, -0.2, 0.0, 0.5 * std::log(sn2);
  const Matrix Xu = 2.0 * Matrix::Random(M, D);
  const Vector theta = FitcLayout{D, M}.pack(hyper, Xu);
  hyper(D + 1) = 0.5 * std::log(sn2 + c);
  const Vector larger = FitcLayout{D, M}.pack(hyper, Xu);
  const double known = FitcLikelihood(X, r, M, FitcJitter::fixed(1e-8), {}, 1, Vector::Constant(N, c)).evaluate(theta).value;
  const double learned = FitcLikelihood(X, r, M, FitcJitter::fixed(1e-8)).evaluate(larger).value;
  EXPECT_NEAR(known, learned, 1e-11 * std::abs(learned));
}

TEST(FitcKnownNoise, PseudoInputsAtTheTrainingInputsGiveTheExactGpWithTheSameKnownNoise) {
  // The reduction of FitcReduction above, with v: Qff + Lambda = Kff + diag(sn2 + v) up to the jitter,
  // against the exact backend's known noise (itself checked against scikit-learn's per-sample alpha).
  const int N = 60, D = 2;
  TrainingSet data{3.0 * Matrix::Random(N, D), Vector(N)};
  data.targets = data.inputs.col(0).array().sin() * data.inputs.col(1).array().cos();
  data.noise_variance = (0.02 * (Vector::Random(N).array() + 1.5)).matrix();
  Vector hyper(D + 2);
  hyper << std::log(1.2), std::log(0.9), std::log(0.8), std::log(0.05);
  FitcOptions options;
  options.jitter = FitcJitter::fixed(1e-10);
  const auto fitc = FitcBackend(options).condition(data, FitcLayout{D, N}.pack(hyper, data.inputs));
  expect_the_exact_gp(*fitc, data, hyper);
  // A fit through the backend takes the known noise (no longer refused).
  FitcOptions fit_options;
  fit_options.inducing = 10;
  FitOptions fit;
  fit.restarts = 0;
  fit.max_evaluations = 40;
  const FitResult result = FitcBackend(fit_options).fit(data, fit);
  EXPECT_TRUE(std::isfinite(result.summary.nlml));
  EXPECT_THROW(FitcLikelihood(data.inputs, data.targets, 5, {}, {}, 1, Vector::Constant(N, -1.0)), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------
// Initialisation of the pseudo-inputs

TEST(FitcInitialisation, KMeansPicksDistinctCentresInsideTheDataAndIsDeterministic) {
  const OracleData o = load_oracle();
  const Matrix& X = o.fit.inputs;  // 200 points
  const Vector scale = initial_hyperparameters(o.fit).lengthscales();
  const Matrix a = initial_pseudo_inputs(X, 15, scale, FitcInitialisation::KMeans, 3);
  const Matrix b = initial_pseudo_inputs(X, 15, scale, FitcInitialisation::KMeans, 3);
  const Matrix c = initial_pseudo_inputs(X, 15, scale, FitcInitialisation::KMeans, 4);
  ASSERT_EQ(a.rows(), 15);
  ASSERT_EQ(a.cols(), X.cols());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  for (Eigen::Index m = 0; m < a.rows(); ++m) {
    EXPECT_TRUE(((a.row(m).array() >= X.colwise().minCoeff().array()) &&
                 (a.row(m).array() <= X.colwise().maxCoeff().array()))
                    .all());
    for (Eigen::Index n = m + 1; n < a.rows(); ++n) EXPECT_GT((a.row(m) - a.row(n)).norm(), 1e-6);
  }
  // Lloyd iterations lower the k-means objective (sum of squared distances to the nearest centre).
  const auto cost = [&](const Matrix& centres) {
    double total = 0;
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      total += (centres.rowwise() - X.row(i))
                   .cwiseQuotient(scale.transpose().replicate(centres.rows(), 1))
                   .rowwise()
                   .squaredNorm()
                   .minCoeff();
    return total;
  };
  const Matrix seeded = initial_pseudo_inputs(X, 15, scale, FitcInitialisation::KMeans, 3, 0);
  EXPECT_LT(cost(a), cost(seeded));
}

TEST(FitcInitialisation, RandomSubsetAndSmallDataUseTrainingInputs) {
  const OracleData o = load_oracle();
  const Matrix& X = o.train.inputs;
  const Vector scale = Vector::Ones(3);
  const Matrix s = initial_pseudo_inputs(X, 6, scale, FitcInitialisation::RandomSubset, 9);
  std::set<Eigen::Index> rows;
  for (Eigen::Index m = 0; m < s.rows(); ++m) {
    bool found = false;
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      if (X.row(i) == s.row(m)) {
        found = true;
        rows.insert(i);
      }
    EXPECT_TRUE(found);
  }
  EXPECT_EQ(rows.size(), 6u);
  EXPECT_EQ(initial_pseudo_inputs(X, 20, scale, FitcInitialisation::KMeans, 1), X);
  EXPECT_EQ(initial_pseudo_inputs(X, 50, scale, FitcInitialisation::KMeans, 1), X);
  EXPECT_THROW((void)initial_pseudo_inputs(X, 0, scale, FitcInitialisation::KMeans, 1),
               std::invalid_argument);
  EXPECT_THROW((void)initial_pseudo_inputs(X, 3, Vector::Ones(2), FitcInitialisation::KMeans, 1),
               std::invalid_argument);
  EXPECT_THROW((void)initial_pseudo_inputs(X, 3, -scale, FitcInitialisation::KMeans, 1),
               std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------
// The backend

TEST(FitcBackendTest, FitMovesThePseudoInputsAndLowersTheNlml) {
  const OracleData o = load_oracle();
  FitcOptions fitc;
  fitc.inducing = 10;
  FitOptions options;
  options.restarts = 0;
  options.max_evaluations = 150;
  const FitResult result = FitcBackend(fitc).fit(o.fit, options);
  EXPECT_LT(result.summary.nlml, result.summary.initial_nlml) << result.summary.one_line();
  EXPECT_EQ(result.model->parameters().size(), 5 + 10 * 3);
  auto objective = FitcBackend(fitc).objective(o.fit, options);
  const Vector initial = objective->initial_parameters();
  EXPECT_GT((result.model->parameters().tail(30) - initial.tail(30)).norm(), 1e-3);
  // The fitted sparse model predicts the held-out function about as well as the data allow.
  Vector mean, variance;
  result.model->predict(o.test_inputs, mean, variance);
  EXPECT_TRUE(mean.allFinite());
  EXPECT_TRUE((variance.array() >= 0.0).all());
}

TEST(FitcBackendTest, FixedPseudoInputsStayWhereTheyStarted) {
  const OracleData o = load_oracle();
  FitcOptions fitc;
  fitc.inducing = 8;
  fitc.optimise_pseudo_inputs = false;
  FitOptions options;
  options.restarts = 0;
  options.max_evaluations = 60;
  const auto backend = FitcBackend(fitc);
  const Vector initial = backend.objective(o.fit, options)->initial_parameters();
  const FitResult result = backend.fit(o.fit, options);
  EXPECT_EQ(result.model->parameters().tail(24), initial.tail(24));
  EXPECT_LT(result.summary.nlml, result.summary.initial_nlml);
}

TEST(FitcBackendTest, ObjectiveBoundsAndInitialValuesAreConsistent) {
  const OracleData o = load_oracle();
  FitcOptions fitc;
  fitc.inducing = 50;  // more than N = 20: min(M, N) pseudo-inputs, on the training inputs
  const auto objective = FitcBackend(fitc).objective(o.train, FitOptions{});
  EXPECT_EQ(objective->parameter_count(), 5 + 20 * 3);
  EXPECT_EQ(objective->input_dim(), 3);
  const Vector initial = objective->initial_parameters();
  const ParameterBounds b = objective->bounds();
  EXPECT_TRUE((initial.array() >= b.lower.array()).all() && (initial.array() <= b.upper.array()).all());
  EXPECT_EQ((FitcLayout{3, 20}.inducing_inputs(initial)), o.train.inputs);
}

/// GP-ILQG refits warm-started from the previous iteration's model. While the data are fewer than the
/// inducing inputs, FITC's parameter vector grows with them (min(M, N) pseudo-inputs); the refit then
/// starts from the previous kernel hyperparameters with this data's pseudo-inputs.
TEST(FitcBackendTest, AWarmStartWithFewerPseudoInputsContributesItsKernelHyperparameters) {
  const OracleData o = load_oracle();  // N = 20, D = 3
  FitcOptions fitc;
  fitc.inducing = 50;
  const FitcBackend backend(fitc);
  const TrainingSet few = o.train.subset({0, 1, 2, 3, 4, 5, 6, 7});
  FitOptions options;
  options.restarts = 0;
  const FitResult first = backend.fit(few, options);
  ASSERT_EQ(first.model->parameters().size(), 5 + 8 * 3);

  options.warm_start = first.model->parameters();
  options.optimise = false;  // condition on the first start: the warm start as carried over
  const FitResult refit = backend.fit(o.train, options);
  const Vector theta = refit.model->parameters();
  ASSERT_EQ(theta.size(), 5 + 20 * 3);
  const ParameterBounds bounds = backend.objective(o.train, options)->bounds();
  const Vector carried = first.model->parameters().head(5).cwiseMax(bounds.lower.head(5)).cwiseMin(bounds.upper.head(5));
  EXPECT_EQ(theta.head(5), carried) << "the kernel hyperparameters are carried over (within this data's bounds)";
  EXPECT_EQ((FitcLayout{3, 20}.inducing_inputs(theta)), o.train.inputs) << "this data's pseudo-inputs";

  options.warm_start = Vector::Zero(4);  // shorter than the shared hyperparameters: a caller's error
  EXPECT_THROW(backend.fit(o.train, options), std::invalid_argument);
}

TEST(FitcBackendTest, PredictionRequestsComputeOnlyWhatIsAsked) {
  const OracleData o = load_oracle();
  const auto model = FitcBackend().condition(o.train, fitc_oracle_theta(o));
  const Vector z = o.test_inputs.row(1).transpose();
  Prediction full, mean_only, no_gradient;
  model->predict(z, full, PredictionRequest{true, true});
  model->predict(z, mean_only, PredictionRequest{false, true});
  model->predict(z, no_gradient, PredictionRequest{true, false});
  EXPECT_EQ(mean_only.mean, full.mean);
  EXPECT_EQ(mean_only.mean_gradient, full.mean_gradient);
  EXPECT_EQ(mean_only.variance_gradient.size(), 0);
  EXPECT_EQ(no_gradient.variance, full.variance);
  EXPECT_EQ(no_gradient.mean_gradient.size(), 0);
  EXPECT_EQ(full.workspace.cross.size(), 7);  // k(Xu, z)
}

// ---------------------------------------------------------------------------------------------------
// Failure paths

TEST(FitcFailure, BadParametersGiveAFailedStatusNeverNaN) {
  const OracleData o = load_oracle();
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7);
  Vector theta = fitc_oracle_theta(o);
  Vector grad;
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    Vector t = theta;
    t(8) = bad;
    const NlmlEvaluation e = lik.evaluate(t, &grad);
    EXPECT_EQ(e.status, FactorStatus::Failed);
    EXPECT_EQ(e.value, std::numeric_limits<double>::infinity());
    EXPECT_EQ(grad, Vector::Zero(theta.size()));
  }
  Vector huge = theta;
  huge(3) = 400.0;  // sf^2 = exp(800) overflows
  EXPECT_EQ(lik.evaluate(huge, &grad).status, FactorStatus::Failed);
  EXPECT_THROW((void)lik.predictor(huge), std::runtime_error);
  EXPECT_THROW((void)FitcBackend().condition(o.train, huge), std::runtime_error);
  // Tiny noise and tiny length-scales: still a finite value or a clean failure, never NaN.
  Vector tiny = theta;
  tiny.head(3).setConstant(-20.0);
  tiny(4) = -30.0;
  const NlmlEvaluation t = lik.evaluate(tiny, &grad);
  EXPECT_FALSE(std::isnan(t.value));
  EXPECT_TRUE(grad.allFinite());
}

TEST(FitcFailure, SizesAndOptionsAreCheckedWithTheValuesInTheMessage) {
  const OracleData o = load_oracle();
  const FitcLikelihood lik(o.train.inputs, o.train.targets, 7);
  EXPECT_THROW((void)lik.evaluate(Vector::Zero(5)), std::invalid_argument);
  EXPECT_THROW(FitcLikelihood(o.train.inputs, o.train.targets.head(3), 7), std::invalid_argument);
  EXPECT_THROW(FitcLikelihood(o.train.inputs, o.train.targets, 0), std::invalid_argument);
  EXPECT_THROW(FitcLikelihood(o.train.inputs, o.train.targets, 7, FitcJitter::fixed(-1.0)),
               std::invalid_argument);
  auto message = [](auto&& action) {
    try {
      action();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  FitcOptions bad;
  bad.inducing = 0;
  EXPECT_NE(message([&] { FitcBackend b(bad); }).find("FitcOptions::inducing = 0"), std::string::npos);
  bad = FitcOptions{};
  bad.kmeans_iterations = -2;
  EXPECT_NE(message([&] { FitcBackend b(bad); }).find("kmeans_iterations = -2"), std::string::npos);
  // 5 + 7 entries cannot hold whole pseudo-inputs in 3 dimensions.
  EXPECT_NE(message([&] { (void)FitcBackend().condition(o.train, Vector::Zero(12)); }).find("12 entries"),
            std::string::npos);
  Vector nan_theta = fitc_oracle_theta(o);
  nan_theta(0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)FitcBackend().condition(o.train, nan_theta), std::invalid_argument);
}

TEST(FitcFailure, DuplicatePseudoInputsAreConditionedWithReportedJitter) {
  const OracleData o = load_oracle();
  Matrix Xu = oracle_inducing();
  Xu.row(4) = Xu.row(2);
  FitcOptions options;
  options.jitter = FitcJitter::fixed(0.0);
  const auto model = FitcBackend(options).condition(o.train, FitcLayout{3, 7}.pack(o.hyp.pack(), Xu));
  EXPECT_EQ(model->conditioning().status, FactorStatus::JitterAdded);
  EXPECT_GT(model->conditioning().jitter, 0.0);
  Prediction p;
  model->predict(o.test_inputs.row(0).transpose(), p, PredictionRequest{true, true});
  EXPECT_TRUE(std::isfinite(p.mean) && std::isfinite(p.variance));
  EXPECT_TRUE(p.mean_gradient.allFinite() && p.variance_gradient.allFinite());
}

}  // namespace
}  // namespace gpilqg::gp::test

namespace gpilqg::gp::test {
namespace {

/// Data of n points in 3 inputs, y = sin(3 x1) + 0.5 x2 + noise.
TrainingSet wave_data(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  TrainingSet data{Matrix(n, 3), Vector(n)};
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) data.inputs(i, d) = uniform(gen);
    data.targets(i) = std::sin(3.0 * data.inputs(i, 0)) + 0.5 * data.inputs(i, 1) + 0.05 * uniform(gen);
  }
  return data;
}

/// The NLML and its gradient are a function of the data and theta alone: the same bits on every
/// evaluation, whatever the BLAS's buffers or other threads evaluating other objectives at the same
/// time are doing (run, merge and MPI results are compared file against file, bit for bit).
TEST(FitcBackendTest, RepeatedAndConcurrentEvaluationsGiveTheSameBits) {
  struct Setting {
    int points, inducing, threads;
  };
  const std::vector<Setting> settings{{20, 50, 1}, {37, 10, 1}, {150, 30, 2}, {1500, 60, 1}, {1500, 60, 2}};
  auto make = [](const Setting& s) {
    FitcOptions fitc;
    fitc.inducing = s.inducing;
    fitc.threads = s.threads;
    return FitcBackend(fitc).objective(wave_data(s.points, static_cast<unsigned>(s.points)), FitOptions{});
  };
  std::vector<double> values;
  std::vector<Vector> gradients;
  for (const Setting& s : settings) {
    Vector gradient;
    auto objective = make(s);
    values.push_back(objective->evaluate(objective->initial_parameters(), &gradient).value);
    gradients.push_back(gradient);
  }
  // Two threads, each with objectives of its own, evaluate all settings repeatedly in opposite orders.
  std::atomic<int> differing{0};
  auto evaluate_all = [&](bool reverse) {
    std::vector<std::unique_ptr<MarginalLikelihoodObjective>> objectives;
    for (const Setting& s : settings) objectives.push_back(make(s));
    for (int repeat = 0; repeat < 10; ++repeat)
      for (std::size_t k = 0; k < settings.size(); ++k) {
        const std::size_t index = reverse ? settings.size() - 1 - k : k;
        Vector gradient;
        auto& objective = *objectives[index];
        const double value = objective.evaluate(objective.initial_parameters(), &gradient).value;
        if (value != values[index] || gradient != gradients[index]) ++differing;
      }
  };
  std::thread other(evaluate_all, true);
  evaluate_all(false);
  other.join();
  EXPECT_EQ(differing.load(), 0) << "of " << 2 * 10 * settings.size() << " evaluations";
}
}  // namespace
}  // namespace gpilqg::gp::test
