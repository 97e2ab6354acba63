// The tests of system identification in the diagnosis, checked against what they must be
// independently of the code: the chi-square quantiles of the tables, the autocorrelation of white
// noise (inside the 95% band at about 95% of the lags, white by Ljung-Box) and of an AR(1) series
// (rho(1) = its coefficient, not white), hand-computed autocorrelations that spanning an episode
// boundary would change, and free runs: the true model simulates the world, a hidden effect lowers the
// fit of the model without it, a tiny linear model gives the fit computed by hand, the control source
// is the one place the applied controls come from, and a diverging model leaves no NaN.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diagnosis_support.hpp"
#include "gpilqg/experiments/diagnosis/chi_square.hpp"
#include "gpilqg/experiments/diagnosis/free_run.hpp"
#include "gpilqg/experiments/diagnosis/whiteness.hpp"

namespace gpilqg {
namespace {

using diagnosis::autocorrelation;

TEST(DiagnosisChiSquare, QuantilesMatchTheTables) {
  // chi2_0.95(k) from the standard tables (e.g. NIST/SEMATECH e-Handbook 1.3.6.7.4, to 3 decimals;
  // the more digits here from R's qchisq(0.95, k)).
  const std::pair<int, double> table[] = {{1, 3.841459}, {2, 5.991465},  {5, 11.070498},  {10, 18.307038},
                                          {20, 31.410433}, {50, 67.504807}, {100, 124.342113}};
  for (const auto& [k, q] : table) {
    EXPECT_NEAR(diagnosis::chi_square_quantile(0.95, k), q, 1e-5) << k;
    EXPECT_NEAR(diagnosis::chi_square_survival(q, k), 0.05, 1e-7) << k;
  }
  EXPECT_NEAR(diagnosis::chi_square_quantile(0.99, 20), 37.566235, 1e-5);
  // k = 2 is the exponential distribution with mean 2; k = 1 is the square of a standard normal.
  for (double x : {0.1, 1.0, 7.5, 40.0}) {
    EXPECT_NEAR(diagnosis::chi_square_survival(x, 2), std::exp(-x / 2.0), 1e-15) << x;
    EXPECT_NEAR(diagnosis::chi_square_survival(x, 1), std::erfc(std::sqrt(x / 2.0)), 1e-15) << x;
  }
  // Large k: Wilson-Hilferty, k (1 - 2/(9k) + z sqrt(2/(9k)))^3 with z = 1.6448536, is good to 1e-4 there.
  const double k = 2000.0, z = 1.6448536269514722;
  const double wilson_hilferty = k * std::pow(1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k)), 3);
  EXPECT_NEAR(diagnosis::chi_square_quantile(0.95, 2000), wilson_hilferty, 1e-4 * wilson_hilferty);
  EXPECT_EQ(diagnosis::chi_square_survival(0.0, 3), 1.0);
  EXPECT_THROW(diagnosis::chi_square_quantile(0.95, 0), std::invalid_argument);
  EXPECT_THROW(diagnosis::chi_square_quantile(1.0, 3), std::invalid_argument);
}

/// Transitions whose held-out rows carry `series` in episodes of `length` samples (and no training rows).
diagnosis::Transitions heldout_series(const Vector& series, int length) {
  diagnosis::Transitions data;
  const auto N = static_cast<int>(series.size());
  data.x = Matrix::Zero(N, 1);
  for (int t = 0; t < N; ++t) {
    data.episode.push_back(t / length);
    data.heldout.push_back(true);
  }
  return data;
}

TEST(DiagnosisWhiteness, WhiteNoiseStaysInsideTheBandAndIsWhite) {
  // 40 series of 1000 samples in 5 episodes of 200: each of the 20 lags falls outside +-1.96/sqrt(N)
  // with probability about 5% (a little less: n_k < N pairs), and Ljung-Box calls 5% of white series
  // coloured. Binomial bounds: 800 lags, sd 0.8%; 40 series, expected 2 coloured, sd 1.4.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  int inside = 0, lags = 0, white = 0;
  const int N = 1000, L = 20, trials = 40;
  for (int trial = 0; trial < trials; ++trial) {
    Vector r(N);
    for (int t = 0; t < N; ++t) r(t) = 3.0 + 0.5 * normal(rng);  // a mean and a scale change nothing
    const auto data = heldout_series(r, 200);
    const auto w = diagnosis::whiteness_test(data, Matrix(r), {"r"}, L);
    ASSERT_EQ(w.samples, N);
    EXPECT_DOUBLE_EQ(w.band, 1.96 / std::sqrt(N));
    EXPECT_EQ(w.degrees_of_freedom, L);
    EXPECT_NEAR(w.critical_value, 31.410433, 1e-5);
    const auto& s = w.states[0];
    EXPECT_EQ(s.autocorrelation(0), 1.0);
    inside += L - s.outside_band;
    lags += L;
    white += s.white ? 1 : 0;
    EXPECT_EQ(s.white, s.p_value >= 0.05);
  }
  const double share = static_cast<double>(inside) / lags;
  EXPECT_GT(share, 0.925);
  EXPECT_LT(share, 0.99);
  EXPECT_GE(white, trials - 6);
}

/// AR(1) series r_t = phi r_{t-1} + e_t, restarted (from its stationary distribution) in every episode.
Vector ar1(double phi, int episodes, int length, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Vector r(episodes * length);
  for (int e = 0; e < episodes; ++e) {
    double value = normal(rng) / std::sqrt(1.0 - phi * phi);
    for (int t = 0; t < length; ++t) {
      if (t > 0) value = phi * value + normal(rng);
      r(e * length + t) = value;
    }
  }
  return r;
}

TEST(DiagnosisWhiteness, AnAutoregressiveResidualIsNotWhiteAndHasItsLagOneCorrelation) {
  // rho(1) of an AR(1) series estimates phi with standard error sqrt((1 - phi^2) / N) (Bartlett's
  // formula) = 0.6 / sqrt(5000) = 0.0085 and a bias of about -(1 + 4 phi) / N = -0.0008: a tolerance of
  // 0.035 is four standard errors plus the bias. rho(k) = phi^k at the other lags, within the same.
  std::mt19937_64 rng(3);
  const Vector r = ar1(0.8, 5, 1000, rng);
  const auto w = diagnosis::whiteness_test(heldout_series(r, 1000), Matrix(r), {"r"}, 20);
  const auto& s = w.states[0];
  EXPECT_NEAR(s.autocorrelation(1), 0.8, 0.035);
  EXPECT_NEAR(s.autocorrelation(2), 0.64, 0.05);
  EXPECT_FALSE(s.white);
  EXPECT_LT(s.p_value, 1e-10);
  // rho(k) = 0.8^k stands clear of the band 1.96 / sqrt(5000) = 0.028 up to k = 8 (0.17; the estimates'
  // standard error there is about sqrt((1 + phi^2) / (1 - phi^2) / N) = 0.03).
  for (int k = 1; k <= 8; ++k) EXPECT_GT(std::abs(s.autocorrelation(k)), w.band) << k;
  EXPECT_GE(s.outside_band, 8);
}

TEST(DiagnosisWhiteness, AutocorrelationNeverSpansEpisodes) {
  // Two episodes of 4 samples, mean 0, sum of squares 8. Within episodes: lag 1 has 3 + 3 pairs of
  // product -1, rho(1) = -6/8; lag 4 has no pair, rho(4) = 0. Spanning the boundary would add the pair
  // (-1)(-1) at lag 1 (rho(1) = -5/8) and four pairs of product -1 at lag 4 (rho(4) = -4/8).
  const Vector r = (Vector(8) << 1, -1, 1, -1, -1, 1, -1, 1).finished();
  const std::vector<int> episode = {0, 0, 0, 0, 1, 1, 1, 1};
  const Vector rho = autocorrelation(r, episode, 5);
  EXPECT_DOUBLE_EQ(rho(0), 1.0);
  EXPECT_DOUBLE_EQ(rho(1), -0.75);
  EXPECT_DOUBLE_EQ(rho(2), 4.0 / 8.0);
  EXPECT_DOUBLE_EQ(rho(3), -2.0 / 8.0);
  EXPECT_DOUBLE_EQ(rho(4), 0.0);
  EXPECT_DOUBLE_EQ(rho(5), 0.0);
  EXPECT_EQ(diagnosis::lag_pairs(episode, 5), (std::vector<long>{8, 6, 4, 2, 0, 0}));
  // As one episode the same values give the spanning numbers.
  const Vector spanning = autocorrelation(r, std::vector<int>(8, 0), 5);
  EXPECT_DOUBLE_EQ(spanning(1), -5.0 / 8.0);
  EXPECT_DOUBLE_EQ(spanning(4), -4.0 / 8.0);
  // A constant series has nothing to correlate: zeros, never NaN.
  EXPECT_EQ(autocorrelation(Vector::Constant(6, 2.0), std::vector<int>(6, 0), 3), Vector::Zero(4));
}

TEST(DiagnosisWhiteness, UsesTheHeldOutRowsOnlyAndTheTextbookQ) {
  // Training rows: a strongly coloured AR(1); held-out rows: one episode of white noise. Only the
  // held-out rows count, and with one episode Q is Ljung and Box's N (N + 2) sum rho_k^2 / (N - k).
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  const Vector coloured = ar1(0.95, 1, 600, rng);
  Vector white(400);
  for (Eigen::Index t = 0; t < white.size(); ++t) white(t) = normal(rng);
  diagnosis::Transitions data;
  Matrix residual(1000, 1);
  residual << coloured, white;
  for (int t = 0; t < 1000; ++t) {
    data.episode.push_back(t < 600 ? 0 : 1);
    data.heldout.push_back(t >= 600);
  }
  data.x = Matrix::Zero(1000, 1);
  const auto w = diagnosis::whiteness_test(data, residual, {"x"}, 10);
  EXPECT_EQ(w.samples, 400);
  const Vector rho = autocorrelation(white, std::vector<int>(400, 0), 10);
  EXPECT_EQ(w.states[0].autocorrelation, rho);
  double q = 0.0;
  for (int k = 1; k <= 10; ++k) q += rho(k) * rho(k) / (400.0 - k);
  EXPECT_NEAR(w.states[0].ljung_box, 400.0 * 402.0 * q, 1e-9);
  // A zero residual: white, Q = 0, p = 1.
  const auto zero = diagnosis::whiteness_test(data, Matrix::Zero(1000, 1), {"x"}, 10);
  EXPECT_TRUE(zero.states[0].white);
  EXPECT_EQ(zero.states[0].ljung_box, 0.0);
  EXPECT_EQ(zero.states[0].p_value, 1.0);
}

/// x' = a x + u, one state, one control, dt = 1.
class ScalarModel final : public StepModel {
 public:
  explicit ScalarModel(double a) : a_(a) {}
  int state_dim() const override { return 1; }
  int control_dim() const override { return 1; }
  double dt() const override { return 1.0; }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians*, StepWorkspace&) const override {
    x_next(0) = a_ * x(0) + u(0);
  }

 private:
  double a_;
};

Episode scalar_episode(std::vector<double> x, std::vector<double> u) {
  Episode e;
  e.id = 4;
  const auto T = static_cast<Eigen::Index>(x.size());
  e.t = Vector::LinSpaced(T, 0.0, static_cast<double>(T - 1));
  e.x = Eigen::Map<Vector>(x.data(), T);
  e.u = Eigen::Map<Vector>(u.data(), T);
  return e;
}

TEST(DiagnosisFreeRun, FitOfATinyModelIsTheHandComputedOne) {
  // Measured x = 1, 2, 3 under u = 1, 1, 0 (x' = x + u exactly). With a = 1/2 the free run from x_0 = 1
  // predicts 1.5, then 0.75 + 1 = 1.75: |y - y^|^2 = 0.25 + 1.5625 = 1.8125, |y - mean(y)|^2 = 0.5 over
  // the predicted samples y = (2, 3), fit = 100 (1 - sqrt(1.8125 / 0.5)).
  const Episode e = scalar_episode({1, 2, 3}, {1, 1, 0});
  const auto exact = diagnosis::free_run({"exact", std::make_shared<ScalarModel>(1.0), diagnosis::measured_controls}, e);
  EXPECT_EQ(exact.steps, 2);
  EXPECT_FALSE(exact.diverged);
  EXPECT_DOUBLE_EQ(exact.fit_percent(0), 100.0);
  const auto half = diagnosis::free_run({"half", std::make_shared<ScalarModel>(0.5), diagnosis::measured_controls}, e);
  ASSERT_EQ(half.predicted.rows(), 3);
  EXPECT_DOUBLE_EQ(half.predicted(1, 0), 1.5);
  EXPECT_DOUBLE_EQ(half.predicted(2, 0), 1.75);
  EXPECT_NEAR(half.fit_percent(0), 100.0 * (1.0 - std::sqrt(1.8125 / 0.5)), 1e-12);
}

TEST(DiagnosisFreeRun, TheControlSourceIsWhereTheAppliedControlsComeFrom) {
  // A one-sample input delay as a control source: u^_t = u_{t-1} (u^_0 = 0). From x_0 = 1 with
  // x' = x + u^: 1 + 0 = 1, then 1 + 1 = 2.
  const Episode e = scalar_episode({1, 2, 3}, {1, 1, 0});
  const diagnosis::ControlSource delayed = [](const MatrixCRef& u) {
    Matrix out = Matrix::Zero(u.rows(), u.cols());
    out.bottomRows(u.rows() - 1) = u.topRows(u.rows() - 1);
    return out;
  };
  const auto run = diagnosis::free_run({"delayed", std::make_shared<ScalarModel>(1.0), delayed}, e);
  EXPECT_DOUBLE_EQ(run.predicted(1, 0), 1.0);
  EXPECT_DOUBLE_EQ(run.predicted(2, 0), 2.0);
  const diagnosis::ControlSource wrong = [](const MatrixCRef& u) { return Matrix(u.topRows(1)); };
  EXPECT_THROW(diagnosis::free_run({"wrong", std::make_shared<ScalarModel>(1.0), wrong}, e), std::invalid_argument);
}

TEST(DiagnosisFreeRun, ADivergingModelStopsWithAFlagAndNoNaN) {
  // x' = 1e7 x from 1: 1e7, then 1e14 beyond the bound 1e12; stopped after one step.
  const Episode e = scalar_episode({1, 2, 3, 4, 5}, {0, 0, 0, 0, 0});
  const auto run = diagnosis::free_run({"wild", std::make_shared<ScalarModel>(1e7), diagnosis::measured_controls}, e);
  EXPECT_TRUE(run.diverged);
  EXPECT_EQ(run.steps, 1);
  EXPECT_EQ(run.predicted.rows(), 2);
  EXPECT_TRUE(run.predicted.allFinite());
  EXPECT_TRUE(std::isfinite(run.fit_percent(0)));
  // Diverging at the first step: no prediction, fit 0.
  const auto nan_model = diagnosis::free_run({"nan", std::make_shared<ScalarModel>(std::nan("")), diagnosis::measured_controls}, e);
  EXPECT_TRUE(nan_model.diverged);
  EXPECT_EQ(nan_model.steps, 0);
  EXPECT_EQ(nan_model.fit_percent(0), 0.0);
}

TEST(DiagnosisFreeRun, TheTrueModelSimulatesANoiseFreeWorld) {
  // The world is the "sim" preset without noise (integrated with 10 RK4 sub-steps); the model is the
  // same preset with one RK4 step per sample: only the integration differs, the fit is ~100%.
  const ModelSpec world;
  ExcitationSettings settings = default_excitation(*world.build());
  settings.episodes = 3;
  settings.steps = 120;
  settings.observation_std = Vector();
  const MeasurementSet set = simulate_measurements(world.build(), settings).set;
  const auto model = diagnosis::make_step_model(world, Integrator::RK4, settings.dt, 1);
  const auto runs = diagnosis::free_run(set, {0, 1, 2}, {{"sim", model, diagnosis::measured_controls}});
  ASSERT_EQ(runs.size(), 3u);
  for (const auto& run : runs) {
    ASSERT_EQ(run.models.size(), 1u);
    EXPECT_FALSE(run.models[0].diverged);
    EXPECT_EQ(run.models[0].steps, 119);
    for (Eigen::Index i = 0; i < 4; ++i) EXPECT_GT(run.models[0].fit_percent(i), 99.9) << "episode " << run.id << " state " << i;
  }
}

TEST(DiagnosisFreeRun, AHiddenEffectLowersTheFitOfTheModelWithoutIt) {
  // Hidden Coulomb friction of 1 N with actuator and observation noise: the diagnosis proposes it, and
  // on every held-out episode the simulation with it fits the velocities better than without.
  ModelSpec world;
  world = world.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, 1.0));
  const MeasurementSet data = test::hidden_effect_data(world.build(test::actuator_noise(1, 0.02)), 11);
  const diagnosis::DiagnosisReport r = diagnosis::diagnose(data, test::fast_options("cartpole"));
  ASSERT_EQ(r.verdict.status, "explained") << r.verdict.reason;
  ASSERT_EQ(r.free_run.size(), r.heldout_episode_index.size());
  for (const auto& e : r.free_run) {
    ASSERT_EQ(e.models.size(), 3u);
    EXPECT_EQ(e.models[0].model, "sim");
    EXPECT_EQ(e.models[1].model, "sim+effect");
    EXPECT_EQ(e.models[2].model, "sim+GP");
    const Vector sim = e.models[0].fit_percent, with = e.models[1].fit_percent;
    for (Eigen::Index i : {1, 3}) EXPECT_LT(sim(i), with(i)) << "episode " << e.id << " state " << r.state_names[static_cast<std::size_t>(i)];
    EXPECT_LT(sim.sum(), with.sum()) << "episode " << e.id;
    for (const auto& m : e.models) EXPECT_TRUE(m.fit_percent.allFinite());
  }
  // The whiteness of the diagnosed residual is reported for every state, with finite numbers.
  ASSERT_EQ(r.whiteness.states.size(), 4u);
  for (const auto& s : r.whiteness.states) {
    EXPECT_EQ(s.autocorrelation.size(), 21);
    EXPECT_TRUE(std::isfinite(s.ljung_box) && std::isfinite(s.p_value));
  }
}

}  // namespace
}  // namespace gpilqg
