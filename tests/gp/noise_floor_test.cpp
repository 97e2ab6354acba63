/// The residual GP's noise floor from the sensors and the process noise (noise_floor.hpp), and the ARD
/// length-scale box (hyperparameters.hpp), on data whose answer is known.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "../control/linear_models.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/hyperparameters.hpp"
#include "gpilqg/gp/noise_floor.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp::test {
namespace {

constexpr double kNoiseFloorDt = 0.1;

/// A damped oscillator x' = A x + B u with a constant process-noise column on each state, so the
/// residual noise of sensor_noise_floor is the same at every input and the floor is its exact std.
std::shared_ptr<gpilqg::test::LinearStepModel> oscillator(double process_std) {
  Matrix A(2, 2), B(2, 1);
  A << 1.0, kNoiseFloorDt, -0.4 * kNoiseFloorDt, 1.0 - 0.2 * kNoiseFloorDt;
  B << 0.0, kNoiseFloorDt;
  auto model = std::make_shared<gpilqg::test::LinearStepModel>(A, B, kNoiseFloorDt);
  model->additive_std = process_std;
  return model;
}

/// N independent transitions of `world` from random (x, u), measured with sensor noise `sensor`.
struct Transitions {
  Matrix x, u, x_next;  // measured, N x n / N x m / N x n
};
Transitions measure(const StepModel& world, const Vector& sensor, int N, unsigned seed) {
  const int n = world.state_dim(), m = world.control_dim();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Transitions t{Matrix(N, n), Matrix(N, m), Matrix(N, n)};
  DiffusionColumns columns;
  Vector x(n), u(m), next(n);
  for (int r = 0; r < N; ++r) {
    for (int i = 0; i < n; ++i) x(i) = uniform(rng);
    for (int j = 0; j < m; ++j) u(j) = uniform(rng);
    world.step(x, u, next);
    world.noise(x, u, columns, false);
    for (int k = 0; k < columns.count(); ++k) next += columns.columns.col(k) * normal(rng) * std::sqrt(world.dt());
    for (int i = 0; i < n; ++i) {
      t.x(r, i) = x(i) + sensor(i) * normal(rng);
      t.x_next(r, i) = next(i) + sensor(i) * normal(rng);
    }
    t.u.row(r) = u.transpose();
  }
  return t;
}

double sample_std(const Vector& v) { return std::sqrt((v.array() - v.mean()).square().sum() / (v.size() - 1.0)); }

TEST(SensorNoiseFloor, EqualsTheMonteCarloStdOfResidualsWhenTheSimulatorIsRight) {
  // Simulator = world: every residual is pure noise, e' - A e + F xi sqrt(dt), whose std the floor
  // gives in closed form. 40,000 samples estimate a std to about 0.35% (1 / sqrt(2 N)).
  const auto model = oscillator(0.05);
  const Vector sensor = (Vector(2) << 0.002, 0.01).finished();
  const Transitions t = measure(*model, sensor, 40000, 7);
  const ResidualData data = make_residual_data(*model, t.x, t.u, t.x_next);
  const Vector floor = sensor_noise_floor(*model, data, sensor);
  // Closed form: sigma_i^2 + sum_j A_ij^2 sigma_j^2 + dt process^2.
  const Matrix A = (Matrix(2, 2) << 1.0, kNoiseFloorDt, -0.4 * kNoiseFloorDt, 1.0 - 0.2 * kNoiseFloorDt).finished();
  for (int i = 0; i < 2; ++i) {
    const double expected = std::sqrt(sensor(i) * sensor(i) + A.row(i).cwiseAbs2().dot(sensor.cwiseAbs2()) +
                                      kNoiseFloorDt * 0.05 * 0.05);
    EXPECT_NEAR(floor(i), expected, 1e-12 * expected) << "state " << i;
    EXPECT_NEAR(sample_std(data.residuals.col(i)), floor(i), 0.015 * floor(i)) << "state " << i;
  }
}

TEST(SensorNoiseFloor, IsTheSmallestOverTheInputsWhenTheNoiseDependsOnTheControl) {
  // Multiplicative actuator noise sigma_m u b: the floor is taken where |u| is smallest.
  const auto model = oscillator(0.0);
  model->multiplicative_std = 0.3;
  ResidualData data;
  data.inputs = (Matrix(3, 3) << 0.0, 0.0, 2.0, 0.5, 0.1, -0.5, 0.2, 0.3, 1.0).finished();
  data.residuals = Matrix::Zero(3, 2);
  const Vector floor = sensor_noise_floor(*model, data, Vector());
  // b = B / dt = (0, 1): velocity only, std = sqrt(dt) * 0.3 * 0.5 at u = -0.5.
  EXPECT_DOUBLE_EQ(floor(0), 0.0);
  EXPECT_NEAR(floor(1), std::sqrt(kNoiseFloorDt) * 0.3 * 0.5, 1e-15);
}

TEST(SensorNoiseFloor, NamesWhatIsWrongWithItsInputs) {
  const auto model = oscillator(0.0);
  ResidualData data;
  data.inputs = Matrix::Zero(2, 3);
  data.residuals = Matrix::Zero(2, 2);
  EXPECT_THROW(sensor_noise_floor(*model, data, Vector::Constant(3, 0.1)), std::invalid_argument);
  EXPECT_THROW(sensor_noise_floor(*model, data, Vector::Constant(2, -0.1)), std::invalid_argument);
  data.inputs = Matrix::Zero(2, 2);
  EXPECT_THROW(sensor_noise_floor(*model, data, Vector()), std::invalid_argument);
  EXPECT_EQ(sensor_noise_floor(*model, ResidualData{Matrix(0, 3), Matrix(0, 2)}, Vector::Constant(2, 0.1)),
            Vector::Zero(2));
}

TEST(ResidualNoiseFloor, BindsOnNoiseFreeTargetsAndNotOnNoisierOnes) {
  // Targets without noise: left alone the fit drives sn to its numerical floor; with noise_floor it
  // stops there. Output 1 gets noise of std 0.05 > its floor 0.01: the fit finds about 0.05.
  const auto simulator = oscillator(0.0);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const int N = 200;
  ResidualData data{Matrix(N, 3), Matrix(N, 2)};
  for (int r = 0; r < N; ++r) {
    for (int j = 0; j < 3; ++j) data.inputs(r, j) = uniform(rng);
    data.residuals(r, 0) = 0.1 * std::sin(3.0 * data.inputs(r, 0));
    data.residuals(r, 1) = 0.1 * std::cos(2.0 * data.inputs(r, 1)) + 0.05 * normal(rng);
  }
  ResidualModelOptions options;
  options.fit.restarts = 1;
  options.threads = 1;
  const ResidualModel free = ResidualModel::fit(simulator, data, ExactGpBackend{}, options);
  options.noise_floor = (Vector(2) << 0.004, 0.01).finished();
  const ResidualModel floored = ResidualModel::fit(simulator, data, ExactGpBackend{}, options);

  EXPECT_LT(std::sqrt(free.output(0).noise_variance()), 1e-3);
  EXPECT_NEAR(std::sqrt(floored.output(0).noise_variance()), 0.004, 1e-9);
  EXPECT_NEAR(std::sqrt(floored.output(1).noise_variance()), 0.05, 0.01);
  EXPECT_GT(std::sqrt(floored.output(1).noise_variance()), 0.01 * (1.0 + 1e-6));

  options.noise_floor = Vector::Constant(3, 0.01);
  EXPECT_THROW(ResidualModel::fit(simulator, data, ExactGpBackend{}, options), std::invalid_argument);
  options.noise_floor = (Vector(2) << 0.01, -1.0).finished();
  EXPECT_THROW(ResidualModel::fit(simulator, data, ExactGpBackend{}, options), std::invalid_argument);
}

TEST(ResidualNoiseFloor, AFloorAboveTheTargetsSpreadFixesTheNoiseThere) {
  // Sensors configured noisier than the targets vary: sn's box collapses to the floor, the fit runs.
  TrainingSet data;
  data.inputs = Matrix::Random(50, 2);
  data.targets = 1e-3 * data.inputs.col(0);
  FitOptions options;
  options.min_noise_std = 0.1;
  const ParameterBounds b = hyperparameter_bounds(data, options.min_noise_std);
  EXPECT_DOUBLE_EQ(b.lower(3), std::log(0.1));
  EXPECT_DOUBLE_EQ(b.upper(3), std::log(0.1));
  const FitResult fit = ExactGpBackend{}.fit(data, options);
  EXPECT_NEAR(std::sqrt(fit.model->noise_variance()), 0.1, 1e-12);
}

TEST(ArdLengthscaleBox, LetsAnIrrelevantInputReachOneHundredThousandSpreads) {
  // y = sin(2 x0) + noise; x1 is irrelevant. ARD's answer is l1 -> infinity: the box must allow at
  // least 1e5 spreads, and the fit, from its data-driven start and from the warm start it is given,
  // must get there (the old box stopped it at 1e3 spreads). There x1 no longer changes a prediction.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  const int N = 150;
  TrainingSet data;
  data.inputs.resize(N, 2);
  data.targets.resize(N);
  for (int r = 0; r < N; ++r) {
    data.inputs(r, 0) = uniform(rng);
    data.inputs(r, 1) = uniform(rng);
    data.targets(r) = std::sin(2.0 * data.inputs(r, 0)) + 0.05 * normal(rng);
  }
  const double spread1 = std::sqrt((data.inputs.col(1).array() - data.inputs.col(1).mean()).square().mean());
  const ParameterBounds b = hyperparameter_bounds(data);
  EXPECT_GE(std::exp(b.upper(1)), 1e5 * spread1 * (1.0 - 1e-12));

  Hyperparameters warm;
  warm.log_lengthscales = (Vector(2) << std::log(0.5), std::log(1e5 * spread1)).finished();
  warm.log_signal_std = 0.0;
  warm.log_noise_std = std::log(0.05);
  for (const bool warm_started : {false, true}) {
    FitOptions options;
    options.restarts = 0;
    if (warm_started) options.warm_start = warm.pack();
    const FitResult fit = ExactGpBackend{}.fit(data, options);
    const Hyperparameters h = fit.model->hyperparameters();
    EXPECT_GE(std::exp(h.log_lengthscales(1)), 1e5 * spread1) << "warm start " << warm_started;
    EXPECT_LT(std::exp(h.log_lengthscales(0)), 2.0) << "the relevant input keeps a short length-scale";
    EXPECT_NEAR(std::exp(h.log_noise_std), 0.05, 0.015);
    const Vector low = (Vector(2) << 0.3, -2.0).finished(), high = (Vector(2) << 0.3, 2.0).finished();
    Prediction at_low, at_high;
    fit.model->predict(low, at_low);
    fit.model->predict(high, at_high);
    EXPECT_NEAR(at_low.mean, at_high.mean, 1e-9);
  }
}

}  // namespace
}  // namespace gpilqg::gp::test
