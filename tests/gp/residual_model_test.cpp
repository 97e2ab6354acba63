/// The residual model: simulator + GP correction as a StepModel (residual_model.hpp). Cart-pole with
/// the paper's simulator (pole 1 m) and "real world" (pole 1.3 m, finely integrated).

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

#include "gp_test_support.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg::gp::test {
namespace {

constexpr double kResidualDt = 0.05;

std::shared_ptr<const IntegratedStepModel> cartpole_simulator(const ActuatorNoise& noise = {}) {
  return std::make_shared<IntegratedStepModel>(make_system("cartpole", Preset::Simulator, {}, noise), Integrator::RK4,
                                               kResidualDt);
}

/// Episodes of the real cart-pole (RK4 with 10 sub-steps) under random piecewise-constant forces,
/// observed with Gaussian noise of std `observation_noise` on every state.
MeasurementSet real_measurements(int episodes, int steps, unsigned seed, double observation_noise = 1e-4) {
  const IntegratedStepModel real(make_system("cartpole", Preset::RealWorld), Integrator::RK4, kResidualDt, 10);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> force(-6.0, 6.0), start(-0.5, 0.5);
  std::normal_distribution<double> noise(0.0, observation_noise);
  MeasurementSet set;
  set.system = system_signature("cartpole");
  for (int e = 0; e < episodes; ++e) {
    Episode ep;
    ep.id = e;
    ep.t.resize(steps);
    ep.x.resize(steps, 4);
    ep.u.resize(steps, 1);
    Vector x(4);
    x << start(gen), start(gen), start(gen), start(gen);
    double u = 0.0;
    for (int t = 0; t < steps; ++t) {
      if (t % 5 == 0) u = force(gen);
      ep.t(t) = t * kResidualDt;
      for (int i = 0; i < 4; ++i) ep.x(t, i) = x(i) + noise(gen);
      ep.u(t, 0) = u;
      x = real.next(x, Vector::Constant(1, u));
    }
    set.episodes.push_back(std::move(ep));
  }
  return set;
}

class CartPoleResidual : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulator_ = cartpole_simulator(ActuatorNoise{Vector::Constant(1, 0.3), {}, {}});
    const MeasurementSet train = real_measurements(8, 60, 21);
    data_ = new ResidualData(make_residual_data(*simulator_, train));
    held_out_ = new ResidualData(make_residual_data(*simulator_, real_measurements(2, 60, 99)));
    ResidualModelOptions options;
    options.fit.restarts = 1;
    model_ = new ResidualModel(ResidualModel::fit(simulator_, *data_, ExactGpBackend{}, options, &report_));
  }
  static void TearDownTestSuite() {
    delete model_;
    delete data_;
    delete held_out_;
  }
  static inline std::shared_ptr<const IntegratedStepModel> simulator_;
  static inline ResidualData* data_ = nullptr;
  static inline ResidualData* held_out_ = nullptr;
  static inline ResidualModel* model_ = nullptr;
  static inline ResidualFitReport report_;
};

TEST_F(CartPoleResidual, CorrectsTheSimulatorOnHeldOutData) {
  ASSERT_EQ(report_.outputs.size(), 4u);
  for (const auto& s : report_.outputs) {
    EXPECT_EQ(s.training_points, 300) << s.one_line();  // the paper's subsample of 472 rows
    EXPECT_LT(s.nlml, s.initial_nlml) << s.one_line();
  }
  double simulator_error = 0.0, model_error = 0.0;
  Vector predicted(4);
  for (int t = 0; t < held_out_->size(); ++t) {
    const Vector x = held_out_->inputs.row(t).head(4).transpose();
    const Vector u = held_out_->inputs.row(t).tail(1).transpose();
    const Vector measured = simulator_->next(x, u) + held_out_->residuals.row(t).transpose();
    model_->step(x, u, predicted);
    simulator_error += (simulator_->next(x, u) - measured).squaredNorm();
    model_error += (predicted - measured).squaredNorm();
  }
  std::printf("one-step RMS error on held-out data: simulator %.3g, residual model %.3g\n",
              std::sqrt(simulator_error / held_out_->size()), std::sqrt(model_error / held_out_->size()));
  EXPECT_LT(model_error, 0.01 * simulator_error);
}

TEST_F(CartPoleResidual, FarFromDataItIsTheSimulatorWithPriorUncertainty) {
  // A point many length-scales away from the data in every input (the paper's Figure 1, far right).
  Vector z(5);
  for (int d = 0; d < 5; ++d) {
    double longest = 0.0;
    for (int i = 0; i < 4; ++i) longest = std::max(longest, model_->output(i).hyperparameters().lengthscales()(d));
    z(d) = data_->inputs.col(d).maxCoeff() + 40.0 * longest;
  }
  const Vector x = z.head(4), u = z.tail(1);
  Vector model_next(4), sim_next(4);
  StepJacobians model_jac, sim_jac;
  model_jac.resize(4, 1);
  sim_jac.resize(4, 1);
  model_->step(x, u, model_next, &model_jac);
  simulator_->step(x, u, sim_next, &sim_jac);
  EXPECT_TRUE(matrices_near(model_next, sim_next, 1e-12, 1e-14));
  EXPECT_TRUE(matrices_near(model_jac.A, sim_jac.A, 1e-12, 1e-14));
  EXPECT_TRUE(matrices_near(model_jac.B, sim_jac.B, 1e-12, 1e-14));
  DiffusionColumns g;
  model_->uncertainty(x, u, g, true);
  ASSERT_EQ(g.count(), 4);
  for (int i = 0; i < 4; ++i) {
    const double prior_sigma = std::sqrt(model_->output(i).prior_variance() / kResidualDt);
    EXPECT_NEAR(g.columns(i, i), prior_sigma, 1e-12 * prior_sigma);
    EXPECT_TRUE(matrices_near(g.d_dx[static_cast<std::size_t>(i)], Matrix::Zero(4, 4), 1e-12));
  }
  // Near the data the uncertainty is far below the prior.
  model_->uncertainty(data_->inputs.row(10).head(4).transpose(), data_->inputs.row(10).tail(1).transpose(), g, false);
  for (int i = 0; i < 4; ++i) EXPECT_LT(g.columns(i, i), 0.2 * std::sqrt(model_->output(i).prior_variance() / kResidualDt));
}

TEST_F(CartPoleResidual, UncertaintyIsTheGpVarianceInContinuousTimeUnits) {
  const Vector x = data_->inputs.row(3).head(4).transpose(), u = data_->inputs.row(3).tail(1).transpose();
  DiffusionColumns g;
  model_->uncertainty(x, u, g, false);
  EXPECT_EQ(model_->uncertainty_dim(), 4);
  Prediction p;
  for (int i = 0; i < 4; ++i) {
    model_->output(i).predict(data_->inputs.row(3).transpose(), p);
    EXPECT_NEAR(g.columns(i, i) * g.columns(i, i) * kResidualDt, p.variance, 1e-15 + 1e-12 * p.variance);  // G^2 dt = var
    for (int j = 0; j < 4; ++j)
      if (j != i) {
        EXPECT_EQ(g.columns(j, i), 0.0);
      }
  }
}

TEST_F(CartPoleResidual, JacobiansAndUncertaintyDerivativesMatchCentralDifferences) {
  std::mt19937 gen(5);
  for (int trial = 0; trial < 3; ++trial) {
    const int row = static_cast<int>(gen() % static_cast<unsigned>(data_->size()));
    const Vector z0 = data_->inputs.row(row).transpose() + ::gpilqg::test::random_vector(5, -0.05, 0.05, 40 + trial);
    const Vector x = z0.head(4), u = z0.tail(1);
    StepJacobians jac;
    jac.resize(4, 1);
    Vector next(4);
    model_->step(x, u, next, &jac);
    auto step_of = [&](const Vector& z) { return model_->next(z.head(4), z.tail(1)); };
    // Steps of 1e-4: the GP mean carries rounding of about eps |alpha| |k| (alpha = K^-1 r is large on
    // nearly noise-free data), which a smaller step would amplify.
    const Matrix numeric = ::gpilqg::test::numeric_jacobian(step_of, z0, 1e-4);
    EXPECT_TRUE(matrices_near(jac.A, numeric.leftCols(4), 1e-7, 1e-6));
    EXPECT_TRUE(matrices_near(jac.B, numeric.rightCols(1), 1e-7, 1e-6));

    DiffusionColumns g;
    model_->uncertainty(x, u, g, true);
    for (int i = 0; i < 4; ++i) {
      auto sigma_of = [&, i](const Vector& z) {
        DiffusionColumns probe;
        model_->uncertainty(z.head(4), z.tail(1), probe, false);
        return Vector(probe.columns.col(i));
      };
      const Matrix dg = ::gpilqg::test::numeric_jacobian(sigma_of, z0, 1e-4);
      const double scale = 1e-6 * std::max(1.0, g.columns(i, i));
      EXPECT_TRUE(matrices_near(g.d_dx[static_cast<std::size_t>(i)], dg.leftCols(4), scale, 1e-5)) << "column " << i;
      EXPECT_TRUE(matrices_near(g.d_du[static_cast<std::size_t>(i)], dg.rightCols(1), scale, 1e-5)) << "column " << i;
    }
  }
}

/// The model's GPs conditioned again from their fitted parameters and training sets, with or without
/// shared prediction; `subset_first` conditions output 0 on its first 100 points only (other inputs).
ResidualModel rebuilt(const ResidualModel& model, OutputSharing sharing, bool subset_first = false) {
  std::vector<std::unique_ptr<FittedGp>> outputs;
  for (int i = 0; i < model.state_dim(); ++i) {
    TrainingSet data = model.output(i).training_set();
    if (subset_first && i == 0) data = TrainingSet{data.inputs.topRows(100), data.targets.head(100)};
    outputs.push_back(ExactGpBackend{}.condition(data, model.output(i).parameters()));
  }
  return ResidualModel(model.simulator_ptr(), std::move(outputs), sharing);
}

/// Everything step and uncertainty return at (x, u), in the order given (true: step first).
struct StepOutputs {
  Vector next, plain_next, sigma, plain_sigma;
  Matrix A, B;
  std::vector<Matrix> d_dx, d_du;
};
StepOutputs query(const ResidualModel& model, const Vector& x, const Vector& u, bool step_first) {
  StepOutputs o;
  StepJacobians jac;
  jac.resize(4, 1);
  DiffusionColumns g, plain;
  o.next.resize(4);
  o.plain_next.resize(4);
  if (step_first) {  // the derivative pass's order, then the forward pass's at the same point
    model.step(x, u, o.next, &jac);
    model.uncertainty(x, u, g, true);
    model.uncertainty(x, u, plain, false);
    model.step(x, u, o.plain_next);
  } else {
    model.uncertainty(x, u, plain, false);
    model.step(x, u, o.plain_next);
    model.step(x, u, o.next, &jac);
    model.uncertainty(x, u, g, true);
  }
  o.A = jac.A;
  o.B = jac.B;
  o.sigma = g.columns.diagonal();
  o.plain_sigma = plain.columns.diagonal();
  o.d_dx = g.d_dx;
  o.d_du = g.d_du;
  return o;
}

::testing::AssertionResult same_outputs(const StepOutputs& a, const StepOutputs& b) {
  constexpr double kTol = 1e-12;
  for (const auto& [x, y] : {std::pair{&a.next, &b.next}, {&a.plain_next, &b.plain_next}, {&a.sigma, &b.sigma},
                             {&a.plain_sigma, &b.plain_sigma}})
    if (auto r = matrices_near(*x, *y, kTol, kTol); !r) return r;
  if (auto r = matrices_near(a.A, b.A, kTol, kTol); !r) return r << " (A)";
  if (auto r = matrices_near(a.B, b.B, kTol, kTol); !r) return r << " (B)";
  for (std::size_t i = 0; i < a.d_dx.size(); ++i) {
    if (auto r = matrices_near(a.d_dx[i], b.d_dx[i], kTol, kTol); !r) return r << " (dG/dx " << i << ")";
    if (auto r = matrices_near(a.d_du[i], b.d_du[i], kTol, kTol); !r) return r << " (dG/du " << i << ")";
  }
  return ::testing::AssertionSuccess();
}

TEST_F(CartPoleResidual, SharedPredictionEqualsPerOutputPrediction) {
  EXPECT_TRUE(model_->shares_outputs());  // fit conditions every output on one subsample
  const ResidualModel shared = rebuilt(*model_, OutputSharing::Auto);
  const ResidualModel reference = rebuilt(*model_, OutputSharing::Off);
  ASSERT_TRUE(shared.shares_outputs());
  ASSERT_FALSE(reference.shares_outputs());
  // Points near the data, one far from it, and repeats; both call orders; the two models interleaved,
  // so every query of `shared` follows one at another point or of another model (the per-thread cache
  // must never serve a stale entry).
  std::vector<Vector> points;
  for (int k = 0; k < 6; ++k)
    points.push_back(data_->inputs.row(17 * k).transpose() + ::gpilqg::test::random_vector(5, -0.05, 0.05, 60 + k));
  points.push_back(Vector::Constant(5, 40.0));
  points.push_back(points[1]);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Vector x = points[k].head(4), u = points[k].tail(1);
    for (const bool step_first : {true, false}) {
      const StepOutputs expected = query(reference, x, u, step_first);
      EXPECT_TRUE(same_outputs(query(shared, x, u, step_first), expected)) << "point " << k;
      const Vector other = points[(k + 1) % points.size()];
      query(shared, other.head(4), other.tail(1), !step_first);
      EXPECT_TRUE(same_outputs(query(shared, x, u, step_first), expected)) << "point " << k << " again";
    }
  }
}

TEST_F(CartPoleResidual, SharedPredictionIsPerThread) {
  const ResidualModel shared = rebuilt(*model_, OutputSharing::Auto);
  const ResidualModel reference = rebuilt(*model_, OutputSharing::Off);
  std::vector<Vector> points;
  for (int k = 0; k < 8; ++k) points.push_back(data_->inputs.row(11 * k).transpose());
  std::vector<StepOutputs> expected;
  for (const auto& z : points) expected.push_back(query(reference, z.head(4), z.tail(1), true));
  // Two threads walk the points in opposite directions, many times, on the one shared model.
  std::vector<int> mismatches(2, 0);
  auto walk = [&](int t) {
    for (int rep = 0; rep < 20; ++rep)
      for (std::size_t j = 0; j < points.size(); ++j) {
        const std::size_t k = t == 0 ? j : points.size() - 1 - j;
        if (!same_outputs(query(shared, points[k].head(4), points[k].tail(1), rep % 2 == 0), expected[k]))
          ++mismatches[static_cast<std::size_t>(t)];
      }
  };
  std::thread other(walk, 1);
  walk(0);
  other.join();
  EXPECT_EQ(mismatches[0], 0);
  EXPECT_EQ(mismatches[1], 0);
}

TEST_F(CartPoleResidual, OutputsOnDifferentInputsPredictEachOnItsOwn) {
  const ResidualModel mixed = rebuilt(*model_, OutputSharing::Auto, true);
  const ResidualModel reference = rebuilt(*model_, OutputSharing::Off, true);
  EXPECT_FALSE(mixed.shares_outputs());
  const Vector z = data_->inputs.row(3).transpose();
  EXPECT_TRUE(same_outputs(query(mixed, z.head(4), z.tail(1), true), query(reference, z.head(4), z.tail(1), true)));
}

TEST_F(CartPoleResidual, NoiseIsTheSimulators) {
  const Vector x = Vector::Constant(4, 0.1), u = Vector::Constant(1, 0.5);
  DiffusionColumns mine, theirs;
  model_->noise(x, u, mine, true);
  simulator_->noise(x, u, theirs, true);
  EXPECT_EQ(model_->noise_dim(), 1);
  EXPECT_EQ(mine.columns, theirs.columns);
  EXPECT_EQ(mine.d_dx[0], theirs.d_dx[0]);
}

TEST_F(CartPoleResidual, SaveAndLoadReproduceTheModel) {
  const auto file = ::gpilqg::test::temporary_dir("residual_io") / "model.h5";
  save_residual_model(file, "/cartpole/gp_ilqg/gp", *model_);
  const ResidualModel loaded = load_residual_model(file, "/cartpole/gp_ilqg/gp", simulator_, ExactGpBackend{});
  const Vector x = data_->inputs.row(5).head(4).transpose(), u = data_->inputs.row(5).tail(1).transpose();
  EXPECT_EQ(loaded.next(x, u), model_->next(x, u));
  DiffusionColumns a, b;
  loaded.uncertainty(x, u, a, false);
  model_->uncertainty(x, u, b, false);
  EXPECT_EQ(a.columns, b.columns);
  const auto euler = std::make_shared<IntegratedStepModel>(make_system("cartpole"), Integrator::Euler, 0.02);
  EXPECT_THROW((void)load_residual_model(file, "/cartpole/gp_ilqg/gp", euler, ExactGpBackend{}), std::runtime_error);
}

TEST(ResidualData, TargetsAreMeasuredNextStateMinusSimulatorStep) {
  const auto simulator = cartpole_simulator();
  const MeasurementSet set = real_measurements(2, 6, 3, 0.0);
  const ResidualData data = make_residual_data(*simulator, set);
  ASSERT_EQ(data.size(), 10);  // 5 consecutive pairs per episode
  const Episode& e = set.episodes[1];
  const Vector expected = e.x.row(3).transpose() - simulator->next(e.x.row(2).transpose(), e.u.row(2).transpose());
  EXPECT_TRUE(matrices_near(data.residuals.row(5 + 2).transpose(), expected, 1e-15));
  EXPECT_EQ(data.inputs(7, 4), e.u(2, 0));
}

TEST(ResidualModel, FitsFromAMeasurementSetAndRefitsWarmStarted) {
  const auto simulator = cartpole_simulator();
  ResidualModelOptions options;
  options.fit.restarts = 0;
  ResidualFitReport first_report, second_report;
  const ResidualModel first =
      ResidualModel::fit(simulator, real_measurements(3, 30, 8), ExactGpBackend{}, options, &first_report);
  const ResidualData more = make_residual_data(*simulator, real_measurements(4, 30, 9));
  const ResidualData validation = make_residual_data(*simulator, real_measurements(1, 30, 10));
  const ResidualModel second = ResidualModel::fit(simulator, more, ExactGpBackend{}, options, &second_report,
                                                  &validation, &first);
  ASSERT_EQ(second_report.resampling.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(first_report.outputs[static_cast<std::size_t>(i)].training_points, 87);
    EXPECT_GE(second_report.resampling[static_cast<std::size_t>(i)].previous_validation_mse, 0.0);
    EXPECT_FALSE(second_report.resampling[static_cast<std::size_t>(i)].validation_mse.empty());
  }
  // Each refit starts from the previous parameters (start 0) plus the data-driven start.
  for (const FitSummary& s : second_report.outputs) EXPECT_EQ(s.starts, 2) << s.one_line();
}

TEST(ResidualData, DtMismatchAndWrongSystemAreClearErrors) {
  const auto simulator = cartpole_simulator();
  MeasurementSet set = real_measurements(2, 6, 3);
  set.episodes[1].t *= 2.0;
  try {
    (void)make_residual_data(*simulator, set);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("episode 1 has dt = 0.1"), std::string::npos) << e.what();
  }
  set = real_measurements(1, 6, 3);
  set.episodes[0].t *= 1.0 + 1e-8;  // within 1e-6: accepted
  EXPECT_NO_THROW((void)make_residual_data(*simulator, set));
  set.system = system_signature("quadrotor");
  EXPECT_THROW((void)make_residual_data(*simulator, set), std::invalid_argument);
}

/// A one-dimensional world for the paper's Figure 1: the simulator misses a force 0.8 sin(x).
class Drift final : public StepModel {
 public:
  explicit Drift(bool real) : real_(real) {}
  int state_dim() const override { return 1; }
  int control_dim() const override { return 1; }
  double dt() const override { return 0.1; }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef next, StepJacobians* jac, StepWorkspace&) const override {
    next(0) = x(0) + dt() * (u(0) + (real_ ? 0.8 * std::sin(x(0)) : 0.0));
    if (jac != nullptr) {
      jac->resize(1, 1);
      jac->A(0, 0) = 1.0 + (real_ ? dt() * 0.8 * std::cos(x(0)) : 0.0);
      jac->B(0, 0) = dt();
    }
  }
 private:
  bool real_;
};

TEST(ResidualModel, FigureOneNearDataCorrectedFarFromDataSimulator) {
  auto simulator = std::make_shared<Drift>(false);
  const Drift real(true);
  const int n = 60;
  Matrix x(n, 1), u(n, 1), next(n, 1);
  for (int i = 0; i < n; ++i) {
    x(i, 0) = -2.0 + 4.0 * i / (n - 1);
    u(i, 0) = std::sin(3.0 * i);
    next(i, 0) = real.next(x.row(i).transpose(), u.row(i).transpose())(0);
  }
  const ResidualData data = make_residual_data(*simulator, x, u, next);
  ResidualModelOptions options;
  options.threads = 1;
  const ResidualModel model = ResidualModel::fit(simulator, data, ExactGpBackend{}, options);
  Vector v(1), xs(1), us(1);
  us << 0.2;
  xs << 0.7;  // inside the data: the real world's step
  model.step(xs, us, v);
  EXPECT_NEAR(v(0), real.next(xs, us)(0), 1e-3);
  xs << 40.0;  // far outside: the simulator's step, with the prior uncertainty
  model.step(xs, us, v);
  EXPECT_NEAR(v(0), simulator->next(xs, us)(0), 1e-12);
  DiffusionColumns g;
  model.uncertainty(xs, us, g, true);
  EXPECT_NEAR(g.columns(0, 0), std::sqrt(model.output(0).prior_variance() / 0.1), 1e-12);
  EXPECT_THROW(ResidualModel(simulator, {}), std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg::gp::test
