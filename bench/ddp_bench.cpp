// Cost of one DDP iteration at T = 100 for cart-pole and quadrotor, for each variant. Each benchmark
// iteration runs a solve capped at 10 iterations from the same start and reads the solver's own timings:
// one_iteration_us = (time per derivative pass) + (time per backward pass) + (time per forward pass),
// the "one iteration"; solver_us_per_iteration = the whole solve divided by its iterations,
// which also pays for rejected backward passes and several line-search trials early on.
// For Robust-iLQG the model carries n uncertainty columns G = diag(sigma) with derivatives, the shape
// the GP residual model has.

#include <numbers>

#include <benchmark/benchmark.h>

#include "gpilqg/control/ddp_solver.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "ddp_pass_timing.hpp"

namespace {

using namespace gpilqg;

/// A step model plus n diagonal uncertainty columns sigma e_i with zero derivatives.
class WithUncertainty final : public StepModel {
 public:
  explicit WithUncertainty(const StepModel& base) : base_(base) {}
  int state_dim() const override { return base_.state_dim(); }
  int control_dim() const override { return base_.control_dim(); }
  double dt() const override { return base_.dt(); }
  std::unique_ptr<StepWorkspace> make_workspace() const override { return base_.make_workspace(); }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef next, StepJacobians* j, StepWorkspace& workspace) const override {
    base_.step(x, u, next, j, workspace);
  }
  int noise_dim() const override { return base_.noise_dim(); }
  using StepModel::noise;
  void noise(const VectorCRef& x, const VectorCRef& u, DiffusionColumns& out, bool d, StepWorkspace& workspace) const override {
    base_.noise(x, u, out, d, workspace);
  }
  int uncertainty_dim() const override { return base_.state_dim(); }
  using StepModel::uncertainty;
  void uncertainty(const VectorCRef&, const VectorCRef&, DiffusionColumns& out, bool, StepWorkspace&) const override {
    const int n = state_dim();
    if (out.count() != n) out.resize(n, control_dim(), n);
    out.columns = 0.01 * Matrix::Identity(n, n);
  }

 private:
  const StepModel& base_;
};

struct Task {
  std::shared_ptr<IntegratedStepModel> model;
  std::unique_ptr<QuadraticCost> cost;
  Vector x0;
  Matrix u0;
};

Task make_task(const std::string& system) {
  ActuatorNoise noise;
  Task task;
  if (system == "cartpole") {
    noise.multiplicative_std = Vector::Constant(1, 0.1);
    task.model = std::make_shared<IntegratedStepModel>(make_system("cartpole", Preset::Simulator, {}, noise),
                                                       Integrator::Euler, 0.05);
    Vector goal(4);
    goal << 0, 0, std::numbers::pi, 0;
    task.cost = std::make_unique<QuadraticCost>(0.05, Matrix::Zero(4, 4), Matrix::Constant(1, 1, 0.1),
                                                Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(), goal);
    task.x0 = Vector::Zero(4);
    task.u0 = Matrix::Zero(1, 100);
  } else {
    noise.multiplicative_std = Vector::Constant(4, 0.1);
    auto quad = make_system("quadrotor", Preset::Simulator, {}, noise);
    task.model = std::make_shared<IntegratedStepModel>(quad, Integrator::Euler, 0.02);
    Vector start = Vector::Zero(12), goal = Vector::Zero(12);
    start(2) = 5.0;
    goal << 4, 0, 5, 0, 0, 0, 0, 0, 0, 0, 0, 0;
    Vector q = Vector::Ones(12);
    q(2) = 10.0;
    const double hover = 0.5 * 9.81 / 4.0;
    task.cost = std::make_unique<QuadraticCost>(QuadraticCost::tracking(
        0.02, q.asDiagonal(), 0.1 * Matrix::Identity(4, 4), 10.0 * Matrix(q.asDiagonal()),
        straight_line_reference(start, goal, 100), Matrix::Constant(4, 100, hover)));
    task.x0 = start;
    task.u0 = Matrix::Constant(4, 100, hover);
  }
  return task;
}

void BM_DdpIteration(benchmark::State& state, const char* system, DdpVariant variant) {
  const Task task = make_task(system);
  const WithUncertainty robust_model(*task.model);
  DdpProblem problem;
  problem.model = variant == DdpVariant::RobustILQG ? static_cast<const StepModel*>(&robust_model) : task.model.get();
  problem.cost = task.cost.get();
  problem.x0 = task.x0;
  problem.horizon = 100;
  DdpOptions options;
  options.variant = variant;
  options.max_iterations = 10;
  DdpSolver solver(options);
  bench::DdpPassTiming timing;
  for (auto _ : state) {
    const DdpResult r = solver.solve(problem, task.u0);
    timing.add(r);
    benchmark::DoNotOptimize(r.nominal_cost);
  }
  timing.report(state, 1e6, "us");
}

BENCHMARK_CAPTURE(BM_DdpIteration, cartpole_ilqr, "cartpole", DdpVariant::ILQR)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, cartpole_ilqg, "cartpole", DdpVariant::ILQG)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, cartpole_robust_ilqg, "cartpole", DdpVariant::RobustILQG)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, quadrotor_ilqr, "quadrotor", DdpVariant::ILQR)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, quadrotor_ilqg, "quadrotor", DdpVariant::ILQG)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DdpIteration, quadrotor_robust_ilqg, "quadrotor", DdpVariant::RobustILQG)->Unit(benchmark::kMicrosecond);

}  // namespace
