/// No allocation in hot loops (docs/architecture.md#models-and-workspaces): after a warm-up,
/// prediction, the residual model's step and uncertainty with the caller's workspace, and moment
/// matching (PDDP's belief step) do not touch the heap. Counted by interposing glibc's malloc in this
/// test program.

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstddef>
#include <vector>

#include "gp_test_support.hpp"
#include "moment_matching_checks.hpp"
#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/moment_matching.hpp"
#include "gpilqg/gp/residual_model.hpp"

// AddressSanitizer owns malloc itself; under it (GPILQG_SANITIZE) the counter is off and the tests skip.
#if defined(__SANITIZE_ADDRESS__)
#define GPILQG_COUNT_MALLOC 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GPILQG_COUNT_MALLOC 0
#endif
#endif
#ifndef GPILQG_COUNT_MALLOC
#define GPILQG_COUNT_MALLOC 1
#endif

namespace {
std::atomic<long> g_malloc_calls{0};
}  // namespace

#if GPILQG_COUNT_MALLOC
extern "C" void* __libc_malloc(std::size_t size);  // NOLINT: glibc's allocator behind malloc

extern "C" void* malloc(std::size_t size) {  // NOLINT: counts every allocation of the process
  g_malloc_calls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
#define SKIP_WITHOUT_COUNTER() (void)0
#else
#define SKIP_WITHOUT_COUNTER() GTEST_SKIP() << "malloc is AddressSanitizer's here; nothing to count"
#endif

namespace gpilqg::gp::test {
namespace {

TEST(Allocation, TheCounterSeesAllocations) {
  SKIP_WITHOUT_COUNTER();
  const long before = g_malloc_calls.load();
  auto* block = new std::vector<double>(100);
  delete block;
  Vector v(1000);
  v.setZero();
  EXPECT_GE(g_malloc_calls.load() - before, 2);
  // Allocations inside the shared gpilqg libraries reach this program's malloc too.
  const long before_library = g_malloc_calls.load();
  const auto system = make_system("cartpole");
  EXPECT_GE(g_malloc_calls.load() - before_library, 1);
}

TEST(Allocation, PredictionDoesNotAllocateAfterWarmUp) {
  SKIP_WITHOUT_COUNTER();
  const OracleData oracle = load_oracle();
  for (const std::unique_ptr<GpBackend>& backend : {ExactCase::make(), CompactCase::make()}) {
    const auto model = backend->condition(oracle.train, oracle.hyp.pack());
    Prediction p;
    const PredictionRequest full{true, true};
    std::vector<Vector> queries;  // several points: the compact backend's support and reach differ
    for (Eigen::Index i = 0; i < oracle.test_inputs.rows(); ++i) queries.push_back(oracle.test_inputs.row(i).transpose());
    model->predict(queries[0], p, full);  // warm-up
    const long before = g_malloc_calls.load();
    for (int i = 0; i < 10; ++i) {
      const Vector& z = queries[static_cast<std::size_t>(i) % queries.size()];
      model->predict(z, p, full);
      model->predict(z, p, PredictionRequest{false, true});
      model->predict(z, p, PredictionRequest{true, false});
    }
    EXPECT_EQ(g_malloc_calls.load() - before, 0) << backend->name();
  }
}

TEST(Allocation, ResidualModelStepAndUncertaintyDoNotAllocateAfterWarmUp) {
  SKIP_WITHOUT_COUNTER();
  auto simulator = std::make_shared<IntegratedStepModel>(make_system("cartpole"), Integrator::RK4, 0.05);
  ResidualData data;
  data.inputs = Matrix::Random(40, 5);
  data.residuals = 0.01 * Matrix::Random(40, 4);
  ResidualModelOptions options;
  options.fit.optimise = false;
  const ResidualModel model = ResidualModel::fit(simulator, data, ExactGpBackend{}, options);
  ASSERT_TRUE(model.shares_outputs());
  const Vector u = Vector::Constant(1, 0.2);
  Vector x = Vector::Constant(4, 0.1);
  Vector next(4);
  StepJacobians jac;
  jac.resize(4, 1);
  DiffusionColumns g;
  // The caller's workspace (model/data split): the model itself is const and keeps no scratch.
  const auto workspace = model.make_workspace();
  model.step(x, u, next, &jac, *workspace);  // warm-up
  model.uncertainty(x, u, g, true, *workspace);
  const long before = g_malloc_calls.load();
  for (int i = 0; i < 10; ++i) {
    x(0) = 0.01 * i;  // a new query each time (the shared prediction keeps the last one)
    model.step(x, u, next, &jac, *workspace);
    model.step(x, u, next, nullptr, *workspace);
    model.uncertainty(x, u, g, true, *workspace);
  }
  EXPECT_EQ(g_malloc_calls.load() - before, 0);
}

/// Steps with Jacobians and noise columns of `model` at a few states, with one workspace.
long allocations_of_steps(const StepModel& model) {
  const int n = model.state_dim(), m = model.control_dim();
  const auto workspace = model.make_workspace();
  Vector x = Vector::Constant(n, 0.1), next(n);
  const Vector u = Vector::Constant(m, 0.2);
  StepJacobians jac;
  DiffusionColumns columns;
  model.step(x, u, next, &jac, *workspace);  // warm-up
  model.noise(x, u, columns, true, *workspace);
  const long before = g_malloc_calls.load();
  for (int i = 0; i < 10; ++i) {
    x(0) = 0.01 * i;
    model.step(x, u, next, &jac, *workspace);
    model.step(x, u, next, nullptr, *workspace);
    model.noise(x, u, columns, true, *workspace);
  }
  return g_malloc_calls.load() - before;
}

TEST(Allocation, SystemsWithEffectsStepWithoutAllocatingInTheirWorkspace) {
  SKIP_WITHOUT_COUNTER();
  ActuatorNoise noise;
  noise.multiplicative_std = Vector::Constant(1, 0.1);
  ModelSpec cartpole;
  cartpole = cartpole.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, 0.5));
  cartpole = cartpole.with(find_effect("cartpole", "actuator_gain"), Vector::Constant(1, 0.9));
  EXPECT_EQ(allocations_of_steps(*make_step_model(cartpole.build(noise), Integrator::RK4, 0.05, 2)), 0);

  // A MuJoCo model: mj_step and mjd_transitionFD work in the workspace's mjData, and the effects'
  // forces (joint damping here) in the workspace of the system they decorate.
  const std::string arm = (gpilqg::test::source_dir() / "data" / "two_link_arm.xml").string();
  ModelSpec damped;
  damped.system = arm;
  damped = damped.with(find_effect(arm, "joint_viscous_damping:elbow"), Vector::Constant(1, 0.3));
  EXPECT_EQ(allocations_of_steps(*make_step_model(damped.build(), Integrator::RK4, 0.05)), 0);
}

TEST(Allocation, MomentMatchingDoesNotAllocateAfterWarmUp) {
  SKIP_WITHOUT_COUNTER();
  // FITC: per-output centres of different sizes (views into one buffer); SSGP: trigonometric features.
  for (const FittedOutputs& fits : {fitc_outputs(), ssgp_outputs()}) {
    const Vector mu = Vector::Constant(3, 0.1);
    const Matrix sigma = make_sigma(3, 0.3, 1, /*zero_index=*/2);
    const Matrix wider = 2.0 * sigma;
    MomentMatch m;
    fits.matcher->propagate(mu, sigma, m, MomentDerivatives::All);  // warm-up
    const long before = g_malloc_calls.load();
    for (int i = 0; i < 5; ++i) {
      fits.matcher->propagate(mu, wider, m, MomentDerivatives::All);
      fits.matcher->propagate(mu, sigma, m, MomentDerivatives::None);
    }
    EXPECT_EQ(g_malloc_calls.load() - before, 0) << fits.models[0]->backend_name();
  }
}

TEST(Allocation, MomentMatchingOnTwoThreadsDoesNotAllocateAfterWarmUp) {
  SKIP_WITHOUT_COUNTER();
  // 300 shared centres, 3 outputs: large enough that the pairs go to the helper thread (ForkJoin).
  const Matrix inputs = Matrix::Random(300, 3) * 3.0;
  std::vector<SeArdOutput> outputs;
  for (int a = 0; a < 3; ++a)
    outputs.push_back(condition_se_ard_output(inputs, inputs.col(a).array().sin().matrix(), Vector::Zero(3), 0.0,
                                              std::log(0.1)));
  const SeArdMomentMatcher matcher(inputs, outputs);
  const Vector mu = Vector::Constant(3, 0.1);
  const Matrix sigma = make_sigma(3, 0.3, 1, /*zero_index=*/2);
  const Matrix wider = 2.0 * sigma;
  MomentMatch m;
  m.threads = 2;
  matcher.propagate(mu, sigma, m, MomentDerivatives::All);  // warm-up: sizes the buffers, starts the helper
  ASSERT_EQ(m.fork_join.helpers(), 1);
  const long before = g_malloc_calls.load();
  for (int i = 0; i < 5; ++i) {
    matcher.propagate(mu, wider, m, MomentDerivatives::All);
    matcher.propagate(mu, sigma, m, MomentDerivatives::None);
  }
  EXPECT_EQ(g_malloc_calls.load() - before, 0);
}

}  // namespace
}  // namespace gpilqg::gp::test
