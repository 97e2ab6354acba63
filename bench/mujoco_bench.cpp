// A MuJoCo model against the analytic cart-pole (same n = 4): one step with Jacobians, and one DDP
// iteration at T = 100 (derivative + backward + forward pass, from the solver's own timers).
//
// The MuJoCo model is data/two_link_arm.xml (timestep 0.01 s): a step of dt = 0.05 s is 5 mj_step
// calls with mjd_transitionFD's centred differences at each (mujoco_system.hpp); the cart-pole's step
// is RK4 with its analytic Jacobians chained through the stages (integrator.hpp), as in `gpilqg run`.
// Run: build/bench/gpilqg_mujoco_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include "ddp_pass_timing.hpp"
#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"

namespace {

using namespace gpilqg;

const std::string kArm = std::string(GPILQG_BENCH_SOURCE_DIR) + "/data/two_link_arm.xml";

std::shared_ptr<const StepModel> model_of(const std::string& system) {
  return make_step_model(make_system(system == "arm" ? kArm : system), Integrator::RK4, 0.05);
}

void BM_StepWithJacobians(benchmark::State& state, const char* system) {
  const auto model = model_of(system);
  const Vector x = Vector::Constant(4, 0.3), u = Vector::Constant(model->control_dim(), 0.5);
  Vector next(4);
  StepJacobians J;
  const auto workspace = model->make_workspace();  // the caller's scratch, as the solvers hold it
  for (auto _ : state) {
    model->step(x, u, next, &J, *workspace);
    benchmark::DoNotOptimize(J.A.data());
  }
}

void BM_DdpIteration(benchmark::State& state, const char* system) {
  const auto model = model_of(system);
  const int m = model->control_dim();
  Vector goal(4);
  if (std::string(system) == "arm") goal << 1.0, 0.8, 0.0, 0.0;
  else goal << 0.0, 0.0, 3.141592653589793, 0.0;
  const QuadraticCost cost(0.05, Matrix::Zero(4, 4), 0.1 * Matrix::Identity(m, m),
                           Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(), goal);
  DdpProblem problem;
  problem.model = model.get();
  problem.cost = &cost;
  problem.x0 = Vector::Zero(4);
  problem.horizon = 100;
  DdpOptions options;
  options.variant = DdpVariant::ILQR;
  options.max_iterations = 10;
  DdpSolver solver(options);
  bench::DdpPassTiming timing;
  for (auto _ : state) {
    const DdpResult r = solver.solve(problem, Matrix::Zero(m, 100));
    timing.add(r);
    benchmark::DoNotOptimize(r.nominal_cost);
  }
  timing.report(state, 1e6, "us");
}

BENCHMARK_CAPTURE(BM_StepWithJacobians, cartpole_rk4_analytic, "cartpole")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StepWithJacobians, mujoco_arm_5_substeps, "arm")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, cartpole_rk4_analytic, "cartpole")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, mujoco_arm_5_substeps, "arm")->Unit(benchmark::kMicrosecond);

}  // namespace
