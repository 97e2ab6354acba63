// Cost of PDDP (control/belief_space.hpp) on GPs learned from data only (gp/gp_belief_dynamics.hpp,
// exact moment matching), one GP per state on N = 300 training points:
//   cart-pole  n = 4,  m = 1, D = 5,  belief dimension 4 + 10 = 14,  dt = 0.05
//   quadrotor  n = 12, m = 4, D = 16, belief dimension 12 + 78 = 90, dt = 0.02
// with three backends (the benchmark name's last part):
//   exact  the SE-ARD GP on all 300 points (SeArdMomentMatcher, shared centres)
//   fitc   FITC with M = 50 pseudo-inputs per output, each output its own (k-means++ on the inputs
//          scaled by the length-scales, a different seed per output; SeArdMomentMatcher, per-output centres)
//   ssgp   SSGP with m = 50 spectral points per output, W ~ N(0, I) with a seed per output (SsgpMomentMatcher)
//
// BM_BeliefStep: one belief propagation v' = F(v, u), without and with the Jacobians dv'/dv, dv'/du
//   (the moment matching plus the chain rule into the packed belief).
// BM_PddpIteration: solve_pddp capped at one iteration (the real engine, variant iLQR over the belief),
//   timed by the solver's own timers as bench/ddp_bench.cpp does: one_iteration_ms = one derivative pass
//   (T propagations with Jacobians, T cost expansions) + one backward pass + one forward pass (T
//   propagations without Jacobians); solver_ms_per_iteration = the whole capped solve, which also pays
//   the initial rollout, the final derivative and gain pass and every line-search trial. The cpu_*
//   counters are the same passes in CPU time (bench/ddp_pass_timing.hpp), the figures to quote on a
//   shared machine.
//
// The data are synthetic transitions of the simulator model (Euler steps of the built-in systems) at
// uniformly drawn states and controls around each task, plus 1e-3 measurement noise, all from a fixed
// seed. The hyperparameters are fixed (no fitting is timed): per output, length-scale l_d = std of input
// column d, sf = std of the output's increments, sn = 0.01 sf (bench/system_samples.hpp); FITC and SSGP
// are conditioned at them with their pseudo-inputs / spectral points as above (GpBackend::condition).
//
// The *_2_threads variants lend the belief step a second thread (GpBeliefDynamics::set_threads: the
// exact GP's output pairs are shared out); they report wall time.
//
// Run e.g. build/bench/gpilqg_pddp_bench --benchmark_min_time=0.2

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "ddp_pass_timing.hpp"
#include "system_samples.hpp"
#include "gpilqg/control/belief_space.hpp"
#include "gpilqg/core/cost.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/fitted_moment_matcher.hpp"
#include "gpilqg/gp/gp_belief_dynamics.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace {

using namespace gpilqg;

constexpr int kTrainingPoints = 300;
constexpr int kSparseSize = 50;  ///< FITC pseudo-inputs and SSGP spectral points per output

struct PddpTask {
  std::unique_ptr<gp::GpBeliefDynamics> dynamics;
  Vector x0, goal;
  Vector u_nominal;  ///< initial controls (constant over the horizon)
  std::string system;
};

/// The fitted GPs of one backend ("fitc" or "ssgp") at the fixed hyperparameters, one per column of
/// `increments` (file comment), and their moment matcher.
std::shared_ptr<const gp::MomentMatcher> sparse_matcher(const std::string& backend, const Matrix& inputs,
                                                       const Matrix& increments) {
  const std::vector<Vector> hyper = bench::fixed_hyperparameters(inputs, increments);
  const int D = static_cast<int>(inputs.cols());
  std::vector<std::unique_ptr<gp::FittedGp>> models;
  std::vector<const gp::FittedGp*> outputs;
  for (Eigen::Index a = 0; a < increments.cols(); ++a) {
    const Vector& h = hyper[static_cast<std::size_t>(a)];
    const gp::TrainingSet data{inputs, increments.col(a)};
    const auto seed = static_cast<std::uint64_t>(100 + a);
    if (backend == "fitc") {
      const Matrix xu = gp::initial_pseudo_inputs(inputs, kSparseSize, h.head(D).array().exp().matrix(),
                                                  gp::FitcInitialisation::KMeans, seed);
      models.push_back(gp::FitcBackend().condition(data, gp::FitcLayout{D, kSparseSize}.pack(h, xu)));
    } else {
      std::mt19937_64 rng(seed);
      std::normal_distribution<double> normal(0.0, 1.0);
      Matrix w(kSparseSize, D);
      for (Eigen::Index i = 0; i < w.size(); ++i) w.data()[i] = normal(rng);
      models.push_back(gp::SsgpBackend().condition(data, gp::SsgpLayout{D, kSparseSize}.pack(h, w)));
    }
    outputs.push_back(models.back().get());
  }
  return gp::moment_matcher_for(outputs);
}

/// N transitions z = [x; u] -> x' - x of the simulator at inputs drawn from the task's box, with
/// measurement noise 1e-3 on the increments; GPs of `backend` with the fixed hyperparameters of
/// system_samples.hpp.
gp::GpBeliefDynamics learn(const StepModel& model, const std::string& system, const std::string& backend) {
  const int n = model.state_dim(), m = model.control_dim(), N = kTrainingPoints;
  const Matrix inputs = bench::draw_inputs(bench::system_box(system), N);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Matrix increments(N, n);
  for (int i = 0; i < N; ++i) {
    const Vector x = inputs.row(i).head(n).transpose(), u = inputs.row(i).tail(m).transpose();
    increments.row(i) = (model.next(x, u) - x).transpose();
    for (int a = 0; a < n; ++a) increments(i, a) += noise(rng);
  }
  if (backend != "exact") return gp::GpBeliefDynamics(n, m, model.dt(), sparse_matcher(backend, inputs, increments));
  return gp::GpBeliefDynamics::condition(n, m, model.dt(), inputs, increments,
                                         bench::fixed_hyperparameters(inputs, increments));
}

PddpTask make_task(const std::string& system, const std::string& backend) {
  PddpTask task;
  task.system = system;
  if (system == "cartpole") {
    const IntegratedStepModel model(make_system("cartpole"), Integrator::Euler, 0.05);
    task.dynamics = std::make_unique<gp::GpBeliefDynamics>(learn(model, system, backend));
    task.x0 = Vector::Zero(4);
    task.goal = Vector(Eigen::Vector4d(0.0, 0.0, std::numbers::pi, 0.0));
    task.u_nominal = Vector::Zero(1);
  } else {
    const IntegratedStepModel model(make_system("quadrotor"), Integrator::Euler, 0.02);
    task.dynamics = std::make_unique<gp::GpBeliefDynamics>(learn(model, system, backend));
    task.x0 = Vector::Zero(12);
    task.x0(2) = 5.0;
    task.goal = task.x0;
    task.goal(0) = 4.0;
    task.u_nominal = Vector::Constant(4, bench::kQuadrotorHover);
  }
  return task;
}

/// The task cost over horizon T: cart-pole swing-up (terminal weights only, as bench/ddp_bench.cpp), the
/// quadrotor tracking a straight line to the goal at hover thrust.
std::unique_ptr<QuadraticCost> make_cost(const PddpTask& task, int T) {
  if (task.system == "cartpole")
    return std::make_unique<QuadraticCost>(0.05, Matrix::Zero(4, 4), Matrix::Constant(1, 1, 0.1),
                                           Vector(Eigen::Vector4d(100, 100, 1000, 100)).asDiagonal(), task.goal);
  Vector q = Vector::Ones(12);
  q(2) = 10.0;
  return std::make_unique<QuadraticCost>(QuadraticCost::tracking(
      0.02, q.asDiagonal(), 0.1 * Matrix::Identity(4, 4), 10.0 * Matrix(q.asDiagonal()),
      straight_line_reference(task.x0, task.goal, T), task.u_nominal.replicate(1, T)));
}

/// A belief with a small covariance, as along a PDDP trajectory (propagation from Sigma = 0 skips nothing,
/// but a nonzero Sigma is the general case).
Vector typical_belief(const PddpTask& task) {
  const int n = static_cast<int>(task.x0.size());
  Vector v(belief_dim(n));
  pack_belief(task.x0 + 0.05 * Vector::Ones(n), 1e-3 * Matrix::Identity(n, n), v);
  return v;
}

void BM_BeliefStep(benchmark::State& state, const char* system, const char* backend, bool with_jacobians,
                   int threads = 1) {
  const PddpTask task = make_task(system, backend);
  task.dynamics->set_threads(threads);
  const Vector v = typical_belief(task);
  Vector v_next(v.size());
  BeliefJacobians jacobians;
  BeliefJacobians* j = with_jacobians ? &jacobians : nullptr;
  task.dynamics->propagate(v, task.u_nominal, v_next, j);  // warm-up: sizes the per-thread buffers
  for (auto _ : state) {
    task.dynamics->propagate(v, task.u_nominal, v_next, j);
    benchmark::DoNotOptimize(v_next.data());
    benchmark::ClobberMemory();
  }
  state.counters["belief_dim"] = static_cast<double>(v.size());
}

void BM_PddpIteration(benchmark::State& state, const char* system, const char* backend, int threads = 1) {
  const int T = static_cast<int>(state.range(0));
  const PddpTask task = make_task(system, backend);
  task.dynamics->set_threads(threads);
  const auto cost = make_cost(task, T);
  const int n = static_cast<int>(task.x0.size());
  const PddpProblem problem{task.dynamics.get(), cost.get(), task.x0, Matrix::Zero(n, n), T, {}, {}};
  const Matrix u0 = task.u_nominal.replicate(1, T);
  DdpOptions options;
  options.max_iterations = 1;
  bench::DdpPassTiming timing;
  for (auto _ : state) {
    double cpu_seconds = 0.0;
    const PddpResult r =
        bench::DdpPassTiming::measure_cpu_seconds([&] { return solve_pddp(problem, u0, options); }, cpu_seconds);
    timing.add(r.belief, cpu_seconds);
    benchmark::DoNotOptimize(r.belief.nominal_cost);
  }
  timing.report(state, 1e3, "ms");
  state.counters["forward_passes_per_solve"] =
      static_cast<double>(timing.forward_passes()) / static_cast<double>(state.iterations());
}

BENCHMARK_CAPTURE(BM_BeliefStep, cartpole, "cartpole", "exact", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_jacobians, "cartpole", "exact", true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor, "quadrotor", "exact", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_jacobians, "quadrotor", "exact", true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_fitc, "cartpole", "fitc", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_jacobians_fitc, "cartpole", "fitc", true)->Unit(benchmark::kMillisecond);
// The same with two threads (MomentMatch::threads; wall time, the figure that counts here).
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_2_threads, "cartpole", "exact", false, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_jacobians_2_threads, "cartpole", "exact", true, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_2_threads, "quadrotor", "exact", false, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_jacobians_2_threads, "quadrotor", "exact", true, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_fitc, "quadrotor", "fitc", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_jacobians_fitc, "quadrotor", "fitc", true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_ssgp, "cartpole", "ssgp", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, cartpole_jacobians_ssgp, "cartpole", "ssgp", true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_ssgp, "quadrotor", "ssgp", false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BeliefStep, quadrotor_jacobians_ssgp, "quadrotor", "ssgp", true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, cartpole, "cartpole", "exact")->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, quadrotor, "quadrotor", "exact")->Arg(50)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, cartpole_2_threads, "cartpole", "exact", 2)->Arg(50)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PddpIteration, cartpole_fitc, "cartpole", "fitc")->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, quadrotor_fitc, "quadrotor", "fitc")->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, cartpole_ssgp, "cartpole", "ssgp")->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PddpIteration, quadrotor_ssgp, "quadrotor", "ssgp")->Arg(50)->Unit(benchmark::kMillisecond);

}  // namespace
