// Cost of the exact GP's units of work at N = 300, 1000, 2000 training points with D = 5 inputs:
// one NLML with its gradient (what every optimiser step pays), a whole fit (L-BFGS, no restarts),
// and one prediction of mean and variance with their input gradients (what every DDP step pays
// per state dimension). Run e.g. build/bench/gpilqg_gp_bench --benchmark_min_time=0.2

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "gpilqg/gp/exact_gp.hpp"

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

Vector typical_parameters() {
  Vector theta(kInputs + 2);
  theta << 0.3, 0.5, 1.0, 0.8, 0.8, 0.0, std::log(0.05);
  return theta;
}

/// The full exact GP (no subsample) on `threads` threads.
ExactGpBackend all_points_backend(int threads = 1) { return ExactGpBackend(ExactGpOptions{ExactGpOptions::kAllPoints, threads}); }

void BM_ExactNlmlWithGradient(benchmark::State& state) {
  const TrainingSet data = synthetic_data(static_cast<int>(state.range(0)));
  auto objective = all_points_backend(static_cast<int>(state.range(1))).objective(data, FitOptions{});
  const Vector theta = typical_parameters();
  Vector gradient;
  for (auto _ : state) {
    const NlmlEvaluation e = objective->evaluate(theta, &gradient);
    benchmark::DoNotOptimize(e.value);
    benchmark::DoNotOptimize(gradient.data());
  }
}
// Arguments: N, threads.
BENCHMARK(BM_ExactNlmlWithGradient)
    ->Args({300, 1})
    ->Args({1000, 1})
    ->Args({2000, 1})
    ->Args({1000, 2})
    ->Args({2000, 2})
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
BENCHMARK(BM_ExactWholeFit)->Arg(300)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond)->Iterations(1);

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
BENCHMARK(BM_ExactPredictionWithGradients)->Arg(300)->Arg(1000)->Arg(2000)->Unit(benchmark::kMicrosecond);

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
BENCHMARK(BM_ExactPredictionMeanOnly)->Arg(300)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
