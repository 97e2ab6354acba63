#include "moment_matching_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>

#include <Eigen/Eigenvalues>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/ssgp.hpp"
#include "test_support.hpp"

namespace gpilqg::gp::test {

using ::gpilqg::test::matrices_near;
using ::gpilqg::test::numeric_jacobian;

Vector stacked_moments(const MomentMatcher& matcher, const Vector& mu, const Matrix& sigma) {
  MomentMatch m;
  matcher.propagate(mu, sigma, m);
  const Eigen::Index e = m.mean.size();
  const Eigen::Index d = mu.size();
  Vector out(e + e * e + d * e);
  out << m.mean, m.covariance.reshaped(), m.cross_covariance.reshaped();
  return out;
}

Matrix make_sigma(int d, double scale, unsigned seed, int zero_index) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Matrix l = Matrix::Zero(d, d);
  for (int i = 0; i < d; ++i) {
    for (int j = 0; j < i; ++j) l(i, j) = 0.4 * scale * normal(gen);
    l(i, i) = scale * (0.6 + 0.2 * std::abs(normal(gen)));
  }
  Matrix sigma = l * l.transpose();
  if (zero_index >= 0) {
    sigma.row(zero_index).setZero();
    sigma.col(zero_index).setZero();
  }
  return sigma;
}

MonteCarloCheck check_against_monte_carlo(const MomentMatcher& matcher, const PosteriorAtPoint& posterior,
                                          const Vector& mu, const Matrix& sigma, int samples,
                                          const std::string& label) {
  const int d = static_cast<int>(mu.size());
  const int e = matcher.output_dim();
  MomentMatch m;
  matcher.propagate(mu, sigma, m);

  // Sample with a factor that tolerates singular Sigma: eigen-decomposition, negative rounding clamped.
  const Eigen::SelfAdjointEigenSolver<Matrix> eig(sigma);
  const Matrix root = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  std::mt19937_64 gen(2024);
  std::normal_distribution<double> normal(0.0, 1.0);
  Matrix dz(samples, d);     // z - mu
  Matrix means(samples, e);  // posterior means m_a(z)
  Matrix vars(samples, e);   // latent variances v_a(z)
  Vector xi(d), mean(e), variance(e);
  for (int s = 0; s < samples; ++s) {
    for (int j = 0; j < d; ++j) xi(j) = normal(gen);
    const Vector delta = root * xi;
    dz.row(s) = delta.transpose();
    posterior(mu + delta, mean, variance);
    means.row(s) = mean.transpose();
    vars.row(s) = variance.transpose();
  }
  const double count = samples;
  const auto mean_and_se = [count](const Vector& terms) {
    const double average = terms.mean();
    const double var = (terms.array() - average).square().sum() / (count - 1.0);
    return std::pair<double, double>{average, std::sqrt(var / count)};
  };
  MonteCarloCheck check;
  const auto compare = [&](const std::string& name, double analytic, const Vector& terms) {
    const auto [mc, se] = mean_and_se(terms);
    const double z = se > 0.0 ? (analytic - mc) / se : (analytic == mc ? 0.0 : INFINITY);
    std::printf("  [%s] %-8s analytic % .6f  MC % .6f  SE %.2e  z % .2f\n", label.c_str(), name.c_str(), analytic,
                mc, se, z);
    if (se == 0.0) {
      EXPECT_NEAR(analytic, mc, 1e-12) << label << " " << name;  // deterministic quantity
    } else {
      EXPECT_LE(std::abs(z), 4.0) << label << " " << name << ": analytic " << analytic << ", MC " << mc
                                  << " +- " << se;
    }
    check.worst_z = std::max(check.worst_z, std::abs(z));
  };
  const Vector sample_means = means.colwise().mean().transpose();
  for (int a = 0; a < e; ++a) compare("M" + std::to_string(a), m.mean(a), means.col(a));
  // S_ab = Cov[m_a, m_b] + delta_ab E[v_a]; per-sample term (m_a - mbar_a)(m_b - mbar_b) + delta_ab v_a.
  for (int a = 0; a < e; ++a)
    for (int b = a; b < e; ++b) {
      Vector terms = (means.col(a).array() - sample_means(a)) * (means.col(b).array() - sample_means(b));
      terms *= count / (count - 1.0);
      if (a == b) terms += vars.col(a);
      compare("S" + std::to_string(a) + std::to_string(b), m.covariance(a, b), terms);
    }
  // C_ka = E[(z_k - mu_k) m_a(z)] (E[z - mu] = 0 exactly, mu known).
  for (int k = 0; k < d; ++k)
    for (int a = 0; a < e; ++a)
      compare("C" + std::to_string(k) + std::to_string(a), m.cross_covariance(k, a),
              dz.col(k).cwiseProduct(means.col(a)));
  std::printf("  [%s] worst |z| = %.2f\n", label.c_str(), check.worst_z);
  return check;
}

void check_derivatives(const MomentMatcher& matcher, const Vector& mu, const Matrix& sigma, const std::string& label,
                       const DifferenceTolerance& tolerance) {
  const int d = static_cast<int>(mu.size());
  const int e = matcher.output_dim();
  MomentMatch m;
  matcher.propagate(mu, sigma, m, MomentDerivatives::All);
  ASSERT_TRUE(m.has_derivatives);

  Matrix analytic_mu(e + e * e + d * e, d);
  analytic_mu << m.dmean_dmu, m.dcovariance_dmu, m.dcross_dmu;
  Matrix analytic_sigma(e + e * e + d * e, d * d);
  analytic_sigma << m.dmean_dsigma, m.dcovariance_dsigma, m.dcross_dsigma;

  const double h = tolerance.step;
  const Matrix numeric_mu =
      numeric_jacobian([&](const Vector& x) { return stacked_moments(matcher, x, sigma); }, mu, h);
  EXPECT_TRUE(matrices_near(analytic_mu, numeric_mu, tolerance.abs, tolerance.rel)) << label << ": d/dmu";

  // One entry of Sigma at a time (unsymmetric perturbations).
  const Vector flat = sigma.reshaped();
  const Matrix numeric_sigma = numeric_jacobian(
      [&](const Vector& x) { return stacked_moments(matcher, mu, x.reshaped(d, d)); }, flat, h);
  EXPECT_TRUE(matrices_near(analytic_sigma, numeric_sigma, tolerance.abs, tolerance.rel)) << label << ": d/dSigma_ij";
  std::printf("  [%s] max |analytic - central difference|: d/dmu %.1e (largest entry %.2f), d/dSigma %.1e "
              "(largest entry %.2f)\n",
              label.c_str(), (analytic_mu - numeric_mu).cwiseAbs().maxCoeff(), analytic_mu.cwiseAbs().maxCoeff(),
              (analytic_sigma - numeric_sigma).cwiseAbs().maxCoeff(), analytic_sigma.cwiseAbs().maxCoeff());

  // Symmetric perturbations Sigma_ij = Sigma_ji = p (a packed covariance): d/dp = d/dSigma_ij + d/dSigma_ji.
  for (int j = 0; j < d; ++j)
    for (int i = j; i < d; ++i) {
      Matrix direction = Matrix::Zero(d, d);
      direction(i, j) = direction(j, i) = 1.0;
      const Vector numeric = (stacked_moments(matcher, mu, sigma + h * direction) -
                              stacked_moments(matcher, mu, sigma - h * direction)) /
                             (2.0 * h);
      Vector expected = analytic_sigma.col(i + d * j);
      if (i != j) expected += analytic_sigma.col(j + d * i);
      EXPECT_TRUE(matrices_near(expected, numeric, tolerance.abs, tolerance.rel))
          << label << ": packed (" << i << ", " << j << ")";
    }
  // d/dSigma_ij == d/dSigma_ji, and S's derivative blocks are symmetric in (a, b).
  for (int j = 0; j < d; ++j)
    for (int i = 0; i < d; ++i)
      EXPECT_TRUE(matrices_near(analytic_sigma.col(i + d * j), analytic_sigma.col(j + d * i), 1e-14, 1e-12));
  for (int a = 0; a < e; ++a)
    for (int b = 0; b < e; ++b) {
      EXPECT_EQ(m.dcovariance_dmu.row(a + e * b), m.dcovariance_dmu.row(b + e * a));
      EXPECT_EQ(m.dcovariance_dsigma.row(a + e * b), m.dcovariance_dsigma.row(b + e * a));
    }
}

TwoOutputData two_output_data() {
  constexpr int n = 60, d = 3;
  TwoOutputData data;
  data.inputs = ::gpilqg::test::random_vector(n * d, -1.5, 1.5, 7).reshaped(n, d);
  data.targets.resize(n, 2);
  std::mt19937 gen(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (int i = 0; i < n; ++i) {
    const auto x = data.inputs.row(i);
    data.targets(i, 0) = std::sin(1.5 * x(0)) + 0.3 * x(1) * x(2) + noise(gen);
    data.targets(i, 1) = 0.5 * std::cos(x(1) + 0.5 * x(2)) - 0.2 * x(0) + noise(gen);
  }
  for (int a = 0; a < 2; ++a) {
    Vector h(d + 2);
    h << std::log(0.9 + 0.2 * a), std::log(1.3 - 0.2 * a), std::log(1.1), std::log(0.8 + 0.3 * a), std::log(0.05);
    data.hyper.push_back(h);
  }
  return data;
}

FittedOutputs::FittedOutputs(std::vector<std::unique_ptr<FittedGp>> fitted) : models(std::move(fitted)) {
  std::vector<const FittedGp*> outputs;
  for (const auto& model : models) outputs.push_back(model.get());
  matcher = moment_matcher_for(outputs);
}

PosteriorAtPoint FittedOutputs::posterior() const {
  return [this](const Vector& z, Vector& mean, Vector& variance) {
    Prediction p;
    for (std::size_t a = 0; a < models.size(); ++a) {
      models[a]->predict(z, p);
      mean(static_cast<Eigen::Index>(a)) = p.mean;
      variance(static_cast<Eigen::Index>(a)) = p.variance;
    }
  };
}

FittedOutputs fitc_outputs() {
  constexpr int d = 3;
  const TwoOutputData data = two_output_data();
  const FitcBackend backend;
  std::vector<std::unique_ptr<FittedGp>> models;
  const int inducing[2] = {8, 11};
  for (int a = 0; a < 2; ++a) {
    const Matrix xu =
        ::gpilqg::test::random_vector(inducing[a] * d, -1.5, 1.5, 20 + a).reshaped(inducing[a], d);
    models.push_back(backend.condition(TrainingSet{data.inputs, data.targets.col(a)},
                                       FitcLayout{d, inducing[a]}.pack(data.hyper[static_cast<std::size_t>(a)], xu)));
  }
  return FittedOutputs(std::move(models));
}

FittedOutputs ssgp_outputs() {
  constexpr int d = 3;
  const TwoOutputData data = two_output_data();
  std::mt19937 gen(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  const SsgpBackend backend;
  std::vector<std::unique_ptr<FittedGp>> models;
  const int frequencies[2] = {10, 7};
  for (int a = 0; a < 2; ++a) {
    Matrix w(frequencies[a], d);
    for (Eigen::Index i = 0; i < w.size(); ++i) w.data()[i] = normal(gen);
    models.push_back(backend.condition(TrainingSet{data.inputs, data.targets.col(a)},
                                       SsgpLayout{d, frequencies[a]}.pack(data.hyper[static_cast<std::size_t>(a)], w)));
  }
  return FittedOutputs(std::move(models));
}

void expect_point_input_is_the_prediction(const FittedOutputs& fits, const std::string& label) {
  const int d = fits.matcher->input_dim();
  const int e = fits.matcher->output_dim();
  MomentMatch m;
  Prediction p;
  for (unsigned trial = 0; trial < 4; ++trial) {
    Vector mu = ::gpilqg::test::random_vector(d, -1.0, 1.0, 100 + trial);
    if (trial == 3) mu *= 3.0;  // outside the data
    fits.matcher->propagate(mu, Matrix::Zero(d, d), m, MomentDerivatives::All);
    for (int a = 0; a < e; ++a) {
      fits.models[static_cast<std::size_t>(a)]->predict(mu, p, PredictionRequest{true, true});
      EXPECT_NEAR(m.mean(a), p.mean, 1e-12 * (1.0 + std::abs(p.mean))) << label << ": output " << a << ", trial " << trial;
      EXPECT_NEAR(m.covariance(a, a), p.variance, 1e-12) << label << ": output " << a << ", trial " << trial;
      EXPECT_TRUE(matrices_near(m.dmean_dmu.row(a).transpose(), p.mean_gradient, 1e-12, 1e-10)) << label;
      for (int b = 0; b < a; ++b) EXPECT_EQ(m.covariance(a, b), 0.0) << label;
    }
    EXPECT_TRUE(m.cross_covariance.isZero(0.0)) << label;
  }
}

void check_moments_and_derivatives(const FittedOutputs& fits, const std::string& label) {
  const MomentMatcher& matcher = *fits.matcher;
  Vector mu(3);
  mu << 0.2, -0.3, 0.1;
  check_against_monte_carlo(matcher, fits.posterior(), mu, make_sigma(3, 0.45, 7), 100000, label + " full Sigma");
  mu << -0.1, 0.4, 0.3;
  check_against_monte_carlo(matcher, fits.posterior(), mu, make_sigma(3, 0.5, 8, /*zero_index=*/2), 100000,
                            label + " zero row 2");
  mu << 0.3, -0.2, 0.5;
  check_derivatives(matcher, mu, make_sigma(3, 0.4, 3), label + " full Sigma");
  check_derivatives(matcher, mu, make_sigma(3, 0.4, 4, /*zero_index=*/1), label + " zero row 1");
  check_derivatives(matcher, mu, Matrix::Zero(3, 3), label + " Sigma = 0");
}

}  // namespace gpilqg::gp::test
