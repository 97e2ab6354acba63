// Cost of the exact GP's units of work at N = 300, 1000, 2000, 4000 training points with D = 5 inputs:
// one NLML with its gradient (what every optimiser step pays; its achieved GFLOP/s against the
// machine's dgemm rate, BM_Dgemm), a whole fit (L-BFGS from the
// data-driven start only: no warm start, no random restarts; N <= 2000, since at N = 4000 one fit
// takes minutes), and one prediction of mean and variance with their input gradients (what every
// DDP step pays per state dimension). Synthetic data with a fixed seed. Run times are fixed in the
// code (MinTime / Iterations / Repetitions), so no flags are needed:
//   build/bench/gpilqg_gp_bench
// The cheap cases run 3 repetitions and report mean, median, stddev, cv and "min" (best of 3: the
// figure least disturbed by other jobs on a shared machine).
// The BM_Residual* cases time the residual model of GP-ILQG per DDP step (see their comment below).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <thread>
#include <vector>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/residual_model.hpp"
#include "system_samples.hpp"

// The BLAS's Fortran interface (LP64), as gp/src/blas_lapack.cpp declares it.
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                       const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
                       const double* beta, double* c, const int* ldc, std::size_t, std::size_t);

namespace {

using gpilqg::Vector;
using namespace gpilqg::gp;

constexpr int kInputs = 5;

/// A smooth function of 5 inputs on [-2, 2]^5 plus noise of std 0.05.
TrainingSet synthetic_data(int n) {
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  TrainingSet data{gpilqg::Matrix(n, kInputs), Vector(n)};
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < kInputs; ++d) data.inputs(i, d) = uniform(gen);
    data.targets(i) = std::sin(data.inputs(i, 0)) * std::cos(0.5 * data.inputs(i, 1)) + 0.3 * data.inputs(i, 2) +
                      0.1 * data.inputs(i, 3) * data.inputs(i, 4) + noise(gen);
  }
  return data;
}

/// Best of the repetitions (the built-in aggregates are mean, median, stddev and cv).
double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

Vector typical_parameters() {
  Vector theta(kInputs + 2);
  theta << 0.3, 0.5, 1.0, 0.8, 0.8, 0.0, std::log(0.05);
  return theta;
}

/// The full exact GP (no subsample) on `threads` threads.
ExactGpBackend all_points_backend(int threads = 1) { return ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints, threads}); }

/// Floating-point operations of one exact NLML with its gradient (exact_objective.cpp), N points, D inputs:
///   Cholesky N^3/3, K^-1 from the factor 2 N^3/3 (dtrtri + dlauum), the two triangular solves for
///   alpha 2 N^2, the kernel matrix's lower triangle N^2/2 (3 D + 2) (a difference, a square and a
///   multiply-add per input, the exponential and sf^2 counted as one each), and the gradient sums
///   N^2/2 (4 D + 4) (W_ij Kf_ij, then per input a difference, a square and a multiply-add).
double exact_nlml_gradient_flops(double n, double d) {
  return n * n * n + 2.0 * n * n + 0.5 * n * n * (3.0 * d + 2.0) + 0.5 * n * n * (4.0 * d + 4.0);
}

void BM_ExactNlmlWithGradient(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const TrainingSet data = synthetic_data(n);
  auto objective = all_points_backend(static_cast<int>(state.range(1))).objective(data, FitOptions{});
  const Vector theta = typical_parameters();
  Vector gradient;
  for (auto _ : state) {
    const NlmlEvaluation e = objective->evaluate(theta, &gradient);
    benchmark::DoNotOptimize(e.value);
    benchmark::DoNotOptimize(gradient.data());
  }
  // Achieved rate (exact_nlml_gradient_flops per wall-clock second), to set against BM_Dgemm's.
  state.counters["GFLOP/s"] = benchmark::Counter(1e-9 * exact_nlml_gradient_flops(n, kInputs) *
                                                 static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate);
}
// Arguments: N, threads. Wall-clock time (UseRealTime) so that threads = 2 is not understated; the
// CPU-time column of the threads = 1 rows is the single-core cost.
BENCHMARK(BM_ExactNlmlWithGradient)
    ->ArgNames({"N", "threads"})
    ->Args({300, 1})
    ->Args({1000, 1})
    ->Args({2000, 1})
    ->Args({1000, 2})
    ->Args({2000, 2})
    ->MinTime(0.3)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// N = 4000: about 8 x the N = 2000 cost per evaluation; one iteration, one repetition.
BENCHMARK(BM_ExactNlmlWithGradient)
    ->ArgNames({"N", "threads"})
    ->Args({4000, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The machine's dgemm rate, the ceiling of the dense work above: C = A B with N x N matrices through
/// the BLAS the GP backends call (libblas.so.3, Fortran interface; docs/building.md#blas), 2 N^3 flops.
/// The library runs every BLAS call on one thread and splits large matrices over its own threads
/// (dense_cholesky.hpp), so threads = 2 here is the same split: each thread one half of C's columns.
void BM_Dgemm(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const gpilqg::Matrix a = gpilqg::Matrix::Random(n, n), b = gpilqg::Matrix::Random(n, n);
  gpilqg::Matrix c(n, n);
  auto columns = [&](int first, int count) {
    const char no = 'N';
    const double one = 1.0, zero = 0.0;
    dgemm_(&no, &no, &n, &count, &n, &one, a.data(), &n, b.data() + static_cast<std::ptrdiff_t>(first) * n, &n,
           &zero, c.data() + static_cast<std::ptrdiff_t>(first) * n, &n, 1, 1);
  };
  for (auto _ : state) {
    if (threads == 1) {
      columns(0, n);
    } else {
      std::thread other(columns, n / 2, n - n / 2);
      columns(0, n / 2);
      other.join();
    }
    benchmark::DoNotOptimize(c.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(2e-9 * n * static_cast<double>(n) * n *
                                                 static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate);
}
// Arguments: N, threads (1, or 2: two single-threaded calls on the halves of C).
BENCHMARK(BM_Dgemm)
    ->ArgNames({"N", "threads"})
    ->Args({2000, 1})
    ->Args({2000, 2})
    ->MinTime(0.3)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ExactWholeFit(benchmark::State& state) {
  const TrainingSet data = synthetic_data(static_cast<int>(state.range(0)));
  FitOptions options;
  options.restarts = 0;
  int evaluations = 0;
  for (auto _ : state) {
    const FitResult fit = all_points_backend().fit(data, options);
    evaluations = fit.summary.evaluations;
    benchmark::DoNotOptimize(fit.model.get());
  }
  state.counters["evaluations"] = evaluations;
}
// One start (the data-driven initial values), at most FitOptions::max_evaluations = 400 evaluations.
BENCHMARK(BM_ExactWholeFit)
    ->ArgNames({"N"})
    ->Arg(300)
    ->Arg(1000)
    ->Arg(2000)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

void BM_ExactPredictionWithGradients(benchmark::State& state) {
  const TrainingSet data = synthetic_data(static_cast<int>(state.range(0)));
  const auto model = all_points_backend().condition(data, typical_parameters());
  Prediction prediction;
  Vector z = Vector::Constant(kInputs, 0.1);
  const PredictionRequest request{true, true};
  model->predict(z, prediction, request);  // warm-up: sizes the workspace
  for (auto _ : state) {
    model->predict(z, prediction, request);
    benchmark::DoNotOptimize(prediction.variance_gradient.data());
    z(0) = -z(0);  // a different query each time
  }
}
BENCHMARK(BM_ExactPredictionWithGradients)
    ->ArgNames({"N"})
    ->Arg(300)
    ->Arg(1000)
    ->Arg(2000)
    ->Arg(4000)
    ->MinTime(0.2)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMicrosecond);

void BM_ExactPredictionMeanOnly(benchmark::State& state) {
  const TrainingSet data = synthetic_data(static_cast<int>(state.range(0)));
  const auto model = all_points_backend().condition(data, typical_parameters());
  Prediction prediction;
  Vector z = Vector::Constant(kInputs, 0.1);
  const PredictionRequest request{false, true};
  model->predict(z, prediction, request);
  for (auto _ : state) {
    model->predict(z, prediction, request);
    benchmark::DoNotOptimize(prediction.mean_gradient.data());
    z(0) = -z(0);
  }
}
BENCHMARK(BM_ExactPredictionMeanOnly)
    ->ArgNames({"N"})
    ->Arg(300)
    ->Arg(1000)
    ->Arg(2000)
    ->MinTime(0.2)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMicrosecond);

// ------------------------------------------------------------------------------------------------
// The GP-ILQG residual model: what one DDP step pays for the learned part. Cart-pole (n = 4, D = 5,
// dt = 0.05) and quadrotor (n = 12, D = 16, dt = 0.02), simulator against the real-world parameters
// (Euler), residuals with measurement noise 1e-3, N = 300 exact GPs, one per state, with the fixed hyperparameters of system_samples.hpp.
// A "derivative step" is what the DDP engine's derivative pass calls per time step: step with A, B and
// uncertainty with its column derivatives, at the same (x, u); a "forward step" what its forward pass
// calls: uncertainty and step without derivatives. The queries cycle through 64 points of the task's box.

gpilqg::gp::ResidualModel residual_model(const std::string& system, gpilqg::gp::OutputSharing sharing) {
  using namespace gpilqg;
  const double dt = system == "cartpole" ? 0.05 : 0.02;
  auto simulator = std::make_shared<IntegratedStepModel>(make_system(system, Preset::Simulator), Integrator::Euler, dt);
  const IntegratedStepModel real(make_system(system, Preset::RealWorld), Integrator::Euler, dt);
  const int n = simulator->state_dim(), m = simulator->control_dim();
  const Matrix inputs = bench::draw_inputs(bench::system_box(system), 300);
  // Measurement noise 1e-3 on the residuals (the position residuals of an Euler step are otherwise 0).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Matrix residuals(inputs.rows(), n);
  for (Eigen::Index i = 0; i < inputs.rows(); ++i) {
    const Vector x = inputs.row(i).head(n).transpose(), u = inputs.row(i).tail(m).transpose();
    residuals.row(i) = (real.next(x, u) - simulator->next(x, u)).transpose();
    for (int a = 0; a < n; ++a) residuals(i, a) += noise(rng);
  }
  const auto hyperparameters = bench::fixed_hyperparameters(inputs, residuals);
  std::vector<std::unique_ptr<FittedGp>> outputs;
  for (int i = 0; i < n; ++i)
    outputs.push_back(all_points_backend().condition(TrainingSet{inputs, residuals.col(i)},
                                                     hyperparameters[static_cast<std::size_t>(i)]));
  return ResidualModel(simulator, std::move(outputs), sharing);
}

void residual_steps(benchmark::State& state, const char* system, bool derivatives, OutputSharing sharing) {
  using namespace gpilqg;
  const ResidualModel model = residual_model(system, sharing);
  const int n = model.state_dim(), m = model.control_dim();
  const Matrix points = bench::draw_inputs(bench::system_box(system), 64, 99);
  Vector next(n);
  StepJacobians jacobians;
  jacobians.resize(n, m);
  DiffusionColumns columns;
  Eigen::Index j = 0;
  for (auto _ : state) {
    const auto x = points.row(j).head(n).transpose();
    const auto u = points.row(j).tail(m).transpose();
    if (derivatives) {
      model.step(x, u, next, &jacobians);
      model.uncertainty(x, u, columns, true);
    } else {
      model.uncertainty(x, u, columns, false);
      model.step(x, u, next);
    }
    benchmark::DoNotOptimize(next.data());
    benchmark::DoNotOptimize(columns.columns.data());
    j = (j + 1) % points.rows();
  }
}

// Each with the outputs' shared prediction (the default) and per output (OutputSharing::Off, the
// reference path and the cost before the sharing).
void BM_ResidualDerivativeStep(benchmark::State& state, const char* system, OutputSharing sharing) {
  residual_steps(state, system, true, sharing);
}
void BM_ResidualForwardStep(benchmark::State& state, const char* system, OutputSharing sharing) {
  residual_steps(state, system, false, sharing);
}
#define GPILQG_RESIDUAL_BENCHMARK(function, name, system, sharing) \
  BENCHMARK_CAPTURE(function, name, system, sharing)                \
      ->MinTime(0.2)                                                \
      ->Repetitions(3)                                              \
      ->ComputeStatistics("min", minimum)                           \
      ->Unit(benchmark::kMicrosecond)
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualDerivativeStep, cartpole_shared, "cartpole", OutputSharing::Auto);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualDerivativeStep, cartpole_per_output, "cartpole", OutputSharing::Off);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualDerivativeStep, quadrotor_shared, "quadrotor", OutputSharing::Auto);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualDerivativeStep, quadrotor_per_output, "quadrotor", OutputSharing::Off);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualForwardStep, cartpole_shared, "cartpole", OutputSharing::Auto);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualForwardStep, cartpole_per_output, "cartpole", OutputSharing::Off);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualForwardStep, quadrotor_shared, "quadrotor", OutputSharing::Auto);
GPILQG_RESIDUAL_BENCHMARK(BM_ResidualForwardStep, quadrotor_per_output, "quadrotor", OutputSharing::Off);

}  // namespace
