// Cost of the model evaluations that every solver iteration repeats T times: f with Jacobians,
// one discrete step with A and B (Euler and RK4), and the noise columns with their derivatives.

#include <benchmark/benchmark.h>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

namespace {

using gpilqg::Vector;

struct Point {
  Vector x, u;
};

Point operating_point(const gpilqg::Dynamics& d) {
  Point p{Vector::Constant(d.state_dim(), 0.3), Vector::Constant(d.control_dim(), 1.2)};
  return p;
}

void BM_DynamicsWithJacobians(benchmark::State& state, const char* system) {
  auto d = gpilqg::make_system(system);
  const Point p = operating_point(*d);
  Vector xdot(d->state_dim());
  gpilqg::DynamicsJacobians jac;
  jac.resize(d->state_dim(), d->control_dim());
  for (auto _ : state) {
    d->evaluate(p.x, p.u, xdot, &jac);
    benchmark::DoNotOptimize(jac.fx.data());
  }
}

void BM_StepWithJacobians(benchmark::State& state, const char* system, gpilqg::Integrator integrator) {
  gpilqg::IntegratedStepModel model(gpilqg::make_system(system), integrator, 0.05);
  const Point p = operating_point(model.dynamics());
  Vector next(model.state_dim());
  gpilqg::StepJacobians jac;
  for (auto _ : state) {
    model.step(p.x, p.u, next, &jac);
    benchmark::DoNotOptimize(jac.A.data());
  }
}

void BM_NoiseColumnsWithDerivatives(benchmark::State& state, const char* system) {
  const auto signature = gpilqg::system_signature(system);
  const int m = static_cast<int>(signature.controls.size());
  gpilqg::ActuatorNoise noise;
  noise.additive_std = Vector::Constant(m, 0.1);
  noise.multiplicative_std = Vector::Constant(m, 0.1);
  auto d = gpilqg::make_system(system, gpilqg::Preset::Simulator, {}, noise);
  const Point p = operating_point(*d);
  gpilqg::DiffusionColumns F;
  for (auto _ : state) {
    d->noise(p.x, p.u, F, true);
    benchmark::DoNotOptimize(F.columns.data());
  }
}

BENCHMARK_CAPTURE(BM_DynamicsWithJacobians, cartpole, "cartpole");
BENCHMARK_CAPTURE(BM_DynamicsWithJacobians, quadrotor, "quadrotor");
BENCHMARK_CAPTURE(BM_StepWithJacobians, cartpole_euler, "cartpole", gpilqg::Integrator::Euler);
BENCHMARK_CAPTURE(BM_StepWithJacobians, cartpole_rk4, "cartpole", gpilqg::Integrator::RK4);
BENCHMARK_CAPTURE(BM_StepWithJacobians, quadrotor_euler, "quadrotor", gpilqg::Integrator::Euler);
BENCHMARK_CAPTURE(BM_StepWithJacobians, quadrotor_rk4, "quadrotor", gpilqg::Integrator::RK4);
BENCHMARK_CAPTURE(BM_NoiseColumnsWithDerivatives, cartpole, "cartpole");
BENCHMARK_CAPTURE(BM_NoiseColumnsWithDerivatives, quadrotor, "quadrotor");

}  // namespace
