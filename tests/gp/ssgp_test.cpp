// Sparse spectrum GP: agreement with the gp_oracle golden numbers (the authors' ssgpr.m and NumPy),
// central differences for every analytic gradient, convergence to the exact GP as the number of
// spectral points grows, the vectorised sincos, the backend (initialisation, fit, prediction API) and
// failure paths. The properties shared with every backend are in backend_typed_test.cpp.

#include "gpilqg/gp/ssgp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "../../gp/src/ssgp_sincos.hpp"  // internal, header-only: tested directly
#include "gp_test_support.hpp"
#include "gpilqg/gp/hyperparameters.hpp"

namespace gpilqg::gp::test {
namespace {

Vector ssgp_oracle_theta(const OracleData& o) {
  return SsgpLayout{3, 10}.pack(o.hyp.pack(), read_numeric_csv(oracle_dir() / "data" / "W.csv"));
}

Matrix standard_normal(int rows, int cols, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Matrix W(rows, cols);
  for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = normal(rng);
  return W;
}

/// Predictions with the oracle's prior mean added (fmu includes m(Xs), dfmu includes cos(xs)).
Predictions predict_with_prior_mean(const SsgpPredictor& p, const Matrix& Xs) {
  const int D = p.input_dim(), m = p.frequencies();
  Predictions out{Vector(Xs.rows()), Vector(Xs.rows()), Matrix(Xs.rows(), D), Matrix(Xs.rows(), D)};
  Vector phi(2 * m), c(2 * m), dm(D), dv(D), dprior(D);
  for (Eigen::Index i = 0; i < Xs.rows(); ++i) {
    const Vector x = Xs.row(i).transpose();
    double mean = 0, var = 0;
    p.predict(x, phi.data(), c.data(), mean, &var, dm.data(), dv.data());
    out.mean(i) = mean + sum_of_sines(x, &dprior);
    out.variance(i) = var;
    out.dmean.row(i) = (dm + dprior).transpose();
    out.dvariance.row(i) = dv.transpose();
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------
// Oracle agreement

TEST(SsgpOracle, MatchesSsgprAndNumpy) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("ssgp");
  const auto numpy = load_oracle_json("python")["numpy_ssgp"];
  const SsgpLikelihood lik(o.train.inputs, o.train.targets, 10);
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(ssgp_oracle_theta(o), &grad);
  EXPECT_EQ(e.status, FactorStatus::Ok);
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(ref["nlml"].get<double>()), 1e-10));
  EXPECT_TRUE(near_relative(scalar(e.value), scalar(numpy["nlml"].get<double>()), 1e-10));
  Vector dhyp(5);
  dhyp << json_matrix(ref["dnlml_logell"]), ref["dnlml_logsf"].get<double>(),
      ref["dnlml_logsn"].get<double>();
  EXPECT_TRUE(near_relative(grad.head(5), dhyp, 1e-10));
  EXPECT_TRUE(near_relative(grad.tail(30).reshaped(10, 3), json_matrix(ref["dnlml_W"]), 1e-10));

  const Predictions p = predict_with_prior_mean(lik.predictor(ssgp_oracle_theta(o)), o.test_inputs);
  EXPECT_TRUE(near_relative(p.mean, json_matrix(ref["fmu"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(ref["fs2"]), 1e-10));
  EXPECT_TRUE(near_relative(p.mean, json_matrix(numpy["fmu"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance, json_matrix(numpy["fs2"]), 1e-10));
  EXPECT_TRUE(near_relative(p.variance.array() + o.hyp.noise_variance(), json_matrix(ref["ys2"]), 1e-10));
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(numpy["dfmu_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(numpy["dfs2_dxs"]), 1e-9, 1e-9));
  EXPECT_TRUE(matrices_near(p.dmean, json_matrix(ref["dfmu_dxs_fd"]), 1e-8, 1e-8));
  EXPECT_TRUE(matrices_near(p.dvariance, json_matrix(ref["dfs2_dxs_fd"]), 1e-8, 1e-8));
}

TEST(SsgpOracle, TheBackendPredictsTheOracleThroughTheInterface) {
  const OracleData o = load_oracle();
  const auto ref = load_oracle_json("ssgp");
  const auto numpy = load_oracle_json("python")["numpy_ssgp"];
  const auto model = SsgpBackend().condition(o.train, ssgp_oracle_theta(o));
  EXPECT_EQ(model->backend_name(), "ssgp");
  EXPECT_EQ(model->conditioning().status, FactorStatus::Ok);
  EXPECT_TRUE(near_relative(scalar(model->negative_log_marginal_likelihood()),
                            scalar(ref["nlml"].get<double>()), 1e-10));
  Prediction p;
  for (Eigen::Index i = 0; i < o.test_inputs.rows(); ++i) {
    const Vector z = o.test_inputs.row(i).transpose();
    model->predict(z, p, PredictionRequest{true, true});
    add_prior_mean(&sum_of_sines, z, p);
    EXPECT_TRUE(near_relative(scalar(p.mean), scalar(json_matrix(ref["fmu"])(i)), 1e-10));
    EXPECT_TRUE(near_relative(scalar(p.variance), scalar(json_matrix(ref["fs2"])(i)), 1e-10));
    EXPECT_TRUE(
        matrices_near(p.mean_gradient.transpose(), json_matrix(numpy["dfmu_dxs"]).row(i), 1e-9, 1e-9));
    EXPECT_TRUE(
        matrices_near(p.variance_gradient.transpose(), json_matrix(numpy["dfs2_dxs"]).row(i), 1e-9, 1e-9));
  }
}

// ---------------------------------------------------------------------------------------------------
// Central differences

TEST(SsgpGradient, EveryParameterMatchesCentralDifferences) {
  const OracleData o = load_oracle();
  Vector theta = ssgp_oracle_theta(o);
  theta.head(5) += Vector::LinSpaced(5, 0.3, -0.2);
  theta.tail(30) += 0.5 * ::gpilqg::test::random_vector(30, -1, 1, 11);
  const SsgpLikelihood lik(o.train.inputs, o.train.targets, 10);
  Vector grad;
  ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
  EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta)));
}

TEST(SsgpGradient, MatchesCentralDifferencesInFiveDimensionsWithManyPoints) {
  const int N = 70, D = 5, m = 15;
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.array().sin().rowwise().sum().matrix() + 0.1 * Vector::Random(N);
  Vector hyper(D + 2);
  hyper << 0.2, 0.5, -0.1, 0.8, 0.3, 0.1, std::log(0.2);
  const SsgpLikelihood lik(X, r, m);
  const Vector theta = SsgpLayout{D, m}.pack(hyper, standard_normal(m, D, 2));
  Vector grad;
  ASSERT_EQ(lik.evaluate(theta, &grad).status, FactorStatus::Ok);
  EXPECT_TRUE(gradient_near(grad, numeric_gradient(lik, theta)));
}

TEST(SsgpGradient, StaysExactWhenTheJitterIsEscalated) {
  // Two identical spectral points give identical feature columns, and with sf = 1e7 the ridge
  // a = m sn2 / sf2 = 1e-15 is below rounding: Phi'Phi + a I is numerically singular and the schedule
  // adds a constant jitter (relative to N/2 = mean(diag(Phi'Phi))). The schedule here starts at 1e-6
  // so that the jittered matrix is well conditioned enough for central differences to be meaningful
  // (with the default 1e-12 its condition number is 1e12 and differences measure rounding).
  // Differences in the hyperparameters only: moving one duplicated point would make it regular.
  const OracleData o = load_oracle();
  Vector hyper = o.hyp.pack();
  hyper(3) = std::log(1e7);
  Matrix W = standard_normal(10, 3, 4);
  W.row(1) = W.row(0);
  const SsgpLikelihood lik(o.train.inputs, o.train.targets, 10, JitterSchedule{1e-6, 1e-2, 10.0});
  const Vector theta = SsgpLayout{3, 10}.pack(hyper, W);
  Vector grad;
  const NlmlEvaluation e = lik.evaluate(theta, &grad);
  ASSERT_EQ(e.status, FactorStatus::JitterAdded);
  EXPECT_NEAR(e.jitter, 1e-6 * 10.0, 1e-12);  // first * N/2
  EXPECT_TRUE(std::isfinite(e.value));
  EXPECT_TRUE(gradient_near(grad.head(5), numeric_gradient(lik, theta).head(5)));
}

TEST(SsgpGradient, TwoThreadsGiveTheSameValueAndGradient) {
  const int N = 1300, D = 3, m = 20;  // >= 500 points per thread, so two blocks are used
  const Matrix X = 2.0 * Matrix::Random(N, D);
  const Vector r = X.array().sin().rowwise().sum().matrix() + 0.1 * Vector::Random(N);
  Vector hyper(D + 2);
  hyper << 0.1, -0.2, 0.3, 0.2, std::log(0.1);
  const Vector theta = SsgpLayout{D, m}.pack(hyper, standard_normal(m, D, 8));
  Vector g1, g2;
  const double v1 = SsgpLikelihood(X, r, m, {}, 1).evaluate(theta, &g1).value;
  const double v2 = SsgpLikelihood(X, r, m, {}, 2).evaluate(theta, &g2).value;
  EXPECT_NEAR(v1, v2, 1e-12 * std::abs(v1));
  EXPECT_TRUE(matrices_near(g2, g1, 1e-11 * g1.cwiseAbs().maxCoeff()));
}

TEST(SsgpGradient, PredictionGradientsMatchCentralDifferences) {
  const OracleData o = load_oracle();
  const SsgpPredictor p = SsgpLikelihood(o.train.inputs, o.train.targets, 10).predictor(ssgp_oracle_theta(o));
  Vector phi(20), c(20), dm(3), dv(3);
  for (const Vector& x : {Vector(o.test_inputs.row(0).transpose()), Vector(Vector::Constant(3, 4.0))}) {
    double mean = 0, var = 0;
    p.predict(x, phi.data(), c.data(), mean, &var, dm.data(), dv.data());
    const Matrix numeric = ::gpilqg::test::numeric_jacobian(
        [&](const Vector& at) {
          Vector v(2);
          p.predict(at, phi.data(), c.data(), v(0), &v(1));
          return v;
        },
        x, 1e-6);
    EXPECT_TRUE(matrices_near(dm.transpose(), numeric.row(0), 1e-8, 1e-6));
    EXPECT_TRUE(matrices_near(dv.transpose(), numeric.row(1), 1e-8, 1e-6));
  }
}

// ---------------------------------------------------------------------------------------------------
// Convergence to the exact GP

TEST(SsgpConvergence, ErrorAgainstTheExactGpFallsAsSpectralPointsAreAdded) {
  // With W ~ N(0, I) the features are a Monte Carlo estimate of the SE kernel (Bochner), so at fixed
  // hyperparameters the SSGP posterior tends to the exact one; the error falls like 1/sqrt(m).
  const int N = 60, D = 3;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  TrainingSet data{Matrix(N, D), Vector(N)};
  for (Eigen::Index i = 0; i < data.inputs.size(); ++i) data.inputs.data()[i] = u(rng);
  data.targets =
      (data.inputs.col(0).array().sin() + 0.5 * data.inputs.col(1).array() * data.inputs.col(2).array().cos())
          .matrix();
  Matrix tests(25, D);
  for (Eigen::Index i = 0; i < tests.size(); ++i) tests.data()[i] = u(rng);
  Vector hyper(D + 2);
  hyper << std::log(1.3), std::log(1.6), std::log(1.1), std::log(1.0), std::log(0.1);
  const auto exact = ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints}).condition(data, hyper);
  Vector mean_exact, var_exact;
  exact->predict(tests, mean_exact, var_exact);

  std::vector<double> mean_error, var_error;
  for (const int m : {10, 50, 200}) {
    double me = 0.0, ve = 0.0;
    const int draws = 6;
    for (int k = 0; k < draws; ++k) {
      const auto model =
          SsgpBackend().condition(data, SsgpLayout{D, m}.pack(hyper, standard_normal(m, D, 100 * m + k)));
      Vector mean, var;
      model->predict(tests, mean, var);
      me += std::sqrt((mean - mean_exact).squaredNorm() / tests.rows()) / draws;
      ve += std::sqrt((var - var_exact).squaredNorm() / tests.rows()) / draws;
    }
    mean_error.push_back(me);
    var_error.push_back(ve);
  }
  EXPECT_GT(mean_error[0], mean_error[1]);
  EXPECT_GT(mean_error[1], mean_error[2]);
  EXPECT_GT(var_error[0], var_error[1]);
  EXPECT_GT(var_error[1], var_error[2]);
  EXPECT_LT(mean_error[2], 0.5 * mean_error[0]);
  EXPECT_LT(mean_error[2], 0.1);  // the targets vary by about 1.5
}

// ---------------------------------------------------------------------------------------------------
// The vectorised sincos

TEST(SsgpSincos, AgreesWithTheStandardLibraryToAFewUlps) {
  std::mt19937_64 rng(5);
  const long n = 4001;
  std::vector<double> z(n), c(n), s(n);
  for (const double scale : {1e-300, 1e-8, 1.0, 50.0, 1e4, 1e6, 1e9}) {
    std::uniform_real_distribution<double> u(-scale, scale);
    for (auto& v : z) v = u(rng);
    z[0] = 0.0;
    z[1] = scale;
    ssgp_detail::sincos_many(z.data(), c.data(), s.data(), n);
    for (long i = 0; i < n; ++i) {
      ASSERT_NEAR(c[i], std::cos(z[i]), 5e-16) << "z = " << z[i];
      ASSERT_NEAR(s[i], std::sin(z[i]), 5e-16) << "z = " << z[i];
      if (std::abs(z[i]) < 1e-3) {
        ASSERT_NEAR(s[i], std::sin(z[i]), 4e-16 * std::abs(z[i])) << "z = " << z[i];
      }
    }
  }
  // In place (the cosines overwrite the arguments), and non-finite arguments stay non-finite.
  std::vector<double> w = {0.5, -2.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()};
  std::vector<double> sines(4);
  ssgp_detail::sincos_many(w.data(), w.data(), sines.data(), 4);
  EXPECT_NEAR(w[0], std::cos(0.5), 5e-16);
  EXPECT_NEAR(sines[1], std::sin(-2.0), 5e-16);
  EXPECT_TRUE(std::isnan(w[2]) && std::isnan(sines[3]));
}

// ---------------------------------------------------------------------------------------------------
// The backend

TEST(SsgpBackendTest, InitialSpectralPointsAreTheBestOfTheDraws) {
  const OracleData o = load_oracle();
  FitOptions fit;
  fit.seed = 17;
  SsgpOptions one, many;
  one.frequencies = many.frequencies = 12;
  one.initial_draws = 1;
  many.initial_draws = 40;
  auto first = SsgpBackend(one).objective(o.fit, fit);
  auto best = SsgpBackend(many).objective(o.fit, fit);
  const Vector a = first->initial_parameters();
  const Vector b = best->initial_parameters();
  EXPECT_EQ(a.head(5), b.head(5));  // same data-driven hyperparameters
  EXPECT_LE(best->evaluate(b, nullptr).value, first->evaluate(a, nullptr).value);
  EXPECT_EQ(b, SsgpBackend(many).objective(o.fit, fit)->initial_parameters());  // deterministic
  const ParameterBounds bounds = best->bounds();
  EXPECT_TRUE(std::isinf(bounds.upper(10)) && std::isinf(bounds.lower(10)));  // W is unbounded
}

TEST(SsgpBackendTest, FitMovesTheSpectralPointsAndLowersTheNlml) {
  const OracleData o = load_oracle();
  SsgpOptions ssgp;
  ssgp.frequencies = 15;
  ssgp.initial_draws = 10;
  FitOptions options;
  options.restarts = 0;
  options.max_evaluations = 150;
  const FitResult result = SsgpBackend(ssgp).fit(o.fit, options);
  EXPECT_LT(result.summary.nlml, result.summary.initial_nlml) << result.summary.one_line();
  EXPECT_EQ(result.model->parameters().size(), 5 + 15 * 3);
  const Vector initial = SsgpBackend(ssgp).objective(o.fit, options)->initial_parameters();
  EXPECT_GT((result.model->parameters().tail(45) - initial.tail(45)).norm(), 1e-3);
  Vector mean, variance;
  result.model->predict(o.test_inputs, mean, variance);
  EXPECT_TRUE(mean.allFinite());
  EXPECT_TRUE((variance.array() >= 0.0).all());
}

TEST(SsgpBackendTest, PredictionRequestsComputeOnlyWhatIsAsked) {
  const OracleData o = load_oracle();
  const auto model = SsgpBackend().condition(o.train, ssgp_oracle_theta(o));
  const Vector z = o.test_inputs.row(3).transpose();
  Prediction full, mean_only, no_gradient;
  model->predict(z, full, PredictionRequest{true, true});
  model->predict(z, mean_only, PredictionRequest{false, true});
  model->predict(z, no_gradient, PredictionRequest{true, false});
  EXPECT_EQ(mean_only.mean, full.mean);
  EXPECT_EQ(mean_only.mean_gradient, full.mean_gradient);
  EXPECT_EQ(mean_only.variance_gradient.size(), 0);
  EXPECT_EQ(no_gradient.variance, full.variance);
  EXPECT_EQ(no_gradient.mean_gradient.size(), 0);
  EXPECT_EQ(full.workspace.cross.size(), 20);  // the 2m features
}

// ---------------------------------------------------------------------------------------------------
// Failure paths

TEST(SsgpFailure, BadParametersGiveAFailedStatusNeverNaN) {
  const OracleData o = load_oracle();
  const SsgpLikelihood lik(o.train.inputs, o.train.targets, 10);
  const Vector theta = ssgp_oracle_theta(o);
  Vector grad;
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()}) {
    Vector t = theta;
    t(20) = bad;
    const NlmlEvaluation e = lik.evaluate(t, &grad);
    EXPECT_EQ(e.status, FactorStatus::Failed);
    EXPECT_EQ(e.value, std::numeric_limits<double>::infinity());
    EXPECT_EQ(grad, Vector::Zero(theta.size()));
  }
  Vector overflow = theta;
  overflow(4) = 400.0;  // sn^2 = exp(800)
  EXPECT_EQ(lik.evaluate(overflow, &grad).status, FactorStatus::Failed);
  EXPECT_THROW((void)lik.predictor(overflow), std::runtime_error);
  EXPECT_THROW((void)SsgpBackend().condition(o.train, overflow), std::runtime_error);
  // Huge frequencies (|z| beyond the fast range) still give finite values.
  Vector fast = theta;
  fast.tail(30) *= 1e7;
  const NlmlEvaluation e = lik.evaluate(fast, &grad);
  EXPECT_TRUE(std::isfinite(e.value));
  EXPECT_TRUE(grad.allFinite());
}

TEST(SsgpFailure, SizesAndOptionsAreCheckedWithTheValuesInTheMessage) {
  const OracleData o = load_oracle();
  const SsgpLikelihood lik(o.train.inputs, o.train.targets, 10);
  EXPECT_THROW((void)lik.evaluate(Vector::Zero(7)), std::invalid_argument);
  EXPECT_THROW(SsgpLikelihood(o.train.inputs, o.train.targets.head(4), 10), std::invalid_argument);
  EXPECT_THROW(SsgpLikelihood(o.train.inputs, o.train.targets, 0), std::invalid_argument);
  auto message = [](auto&& action) {
    try {
      action();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  SsgpOptions bad;
  bad.frequencies = -1;
  EXPECT_NE(message([&] { SsgpBackend b(bad); }).find("SsgpOptions::frequencies = -1"), std::string::npos);
  bad = SsgpOptions{};
  bad.initial_draws = 0;
  EXPECT_NE(message([&] { SsgpBackend b(bad); }).find("initial_draws = 0"), std::string::npos);
  EXPECT_NE(message([&] { (void)SsgpBackend().condition(o.train, Vector::Zero(9)); }).find("9 entries"),
            std::string::npos);
}

}  // namespace
}  // namespace gpilqg::gp::test
