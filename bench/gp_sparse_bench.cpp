// Cost of the sparse GP backends' two hot paths: one negative log marginal likelihood with its full
// analytic gradient (what every optimiser iteration pays), and one prediction of mean and variance
// with their gradients w.r.t. the test input (what every DDP step pays per output).
//
// FITC: N = 5000, D = 5, M = 100 (reference: GPML 4.2 in Octave, 0.058 s per NLML + gradient), and an
// M sweep 50..1000. SSGP: N = 5000, D = 5, m = 100 (reference: ssgpr.m, 0.024 s).
// Run: build/bench/gpilqg_gp_sparse_bench --benchmark_min_time=0.5
// (FitcLikelihood / SsgpLikelihood directly for the NLML; predictions through FittedGp::predict.)

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace {

using gpilqg::Matrix;
using gpilqg::Vector;
namespace gp = gpilqg::gp;

constexpr int kD = 5;

/// N points uniform in [-3, 3]^D with targets sum_d sin(x_d) + 0.1 noise (fixed seed).
gp::TrainingSet make_data(int N) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  gp::TrainingSet data{Matrix(N, kD), Vector(N)};
  for (int i = 0; i < N; ++i) {
    for (int d = 0; d < kD; ++d) data.inputs(i, d) = u(rng);
    data.targets(i) = data.inputs.row(i).array().sin().sum() + noise(rng);
  }
  return data;
}

Vector hyper() {
  Vector h(kD + 2);
  h.head(kD).setConstant(std::log(1.5));
  h(kD) = std::log(1.0);
  h(kD + 1) = std::log(0.1);
  return h;
}

Vector fitc_theta(const gp::TrainingSet& data, int M) {
  const Matrix Xu = data.inputs.topRows(M);  // the points are already in random order
  return gp::FitcLayout{kD, M}.pack(hyper(), Xu);
}

Vector ssgp_theta(int m) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  Matrix W(m, kD);
  for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = normal(rng);
  return gp::SsgpLayout{kD, m}.pack(hyper(), W);
}

void BM_FitcNlmlGradient(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int M = static_cast<int>(state.range(1));
  const int threads = static_cast<int>(state.range(2));
  const gp::TrainingSet data = make_data(N);
  const gp::FitcLikelihood likelihood(data.inputs, data.targets, M, gp::FitcJitter::gpml(), {}, threads);
  const Vector theta = fitc_theta(data, M);
  Vector gradient;
  for (auto _ : state) {
    const gp::NlmlEvaluation e = likelihood.evaluate(theta, &gradient);
    benchmark::DoNotOptimize(e.value);
    benchmark::DoNotOptimize(gradient.data());
  }
  state.counters["params"] = static_cast<double>(theta.size());
}

void BM_FitcNlmlOnly(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int M = static_cast<int>(state.range(1));
  const gp::TrainingSet data = make_data(N);
  const gp::FitcLikelihood likelihood(data.inputs, data.targets, M);
  const Vector theta = fitc_theta(data, M);
  for (auto _ : state) benchmark::DoNotOptimize(likelihood.evaluate(theta).value);
}

void BM_SsgpNlmlGradient(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int m = static_cast<int>(state.range(1));
  const int threads = static_cast<int>(state.range(2));
  const gp::TrainingSet data = make_data(N);
  const gp::SsgpLikelihood likelihood(data.inputs, data.targets, m, {}, threads);
  const Vector theta = ssgp_theta(m);
  Vector gradient;
  for (auto _ : state) {
    const gp::NlmlEvaluation e = likelihood.evaluate(theta, &gradient);
    benchmark::DoNotOptimize(e.value);
    benchmark::DoNotOptimize(gradient.data());
  }
}

/// One prediction with mean, variance and both gradients through the FittedGp interface.
void predict_loop(benchmark::State& state, const gp::FittedGp& model) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  Matrix queries(64, kD);
  for (Eigen::Index i = 0; i < queries.size(); ++i) queries.data()[i] = u(rng);
  gp::Prediction out;
  const gp::PredictionRequest request{true, true};
  Eigen::Index k = 0;
  for (auto _ : state) {
    model.predict(queries.row(k).transpose(), out, request);
    benchmark::DoNotOptimize(out.mean);
    benchmark::DoNotOptimize(out.variance_gradient.data());
    k = (k + 1) % queries.rows();
  }
}

void BM_FitcPredictWithGradients(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int M = static_cast<int>(state.range(1));
  const gp::TrainingSet data = make_data(N);
  const auto model = gp::FitcBackend().condition(data, fitc_theta(data, M));
  predict_loop(state, *model);
}

void BM_SsgpPredictWithGradients(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int m = static_cast<int>(state.range(1));
  const gp::TrainingSet data = make_data(N);
  const auto model = gp::SsgpBackend().condition(data, ssgp_theta(m));
  predict_loop(state, *model);
}

}  // namespace

// Wall-clock time (UseRealTime): with threads = 2 the CPU time of the calling thread alone would
// understate the cost.
BENCHMARK(BM_FitcNlmlGradient)
    ->ArgNames({"N", "M", "threads"})
    ->Args({5000, 100, 1})
    ->Args({5000, 100, 2})
    ->Args({5000, 50, 1})
    ->Args({5000, 200, 1})
    ->Args({5000, 500, 1})
    ->Args({5000, 1000, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitcNlmlOnly)->ArgNames({"N", "M"})->Args({5000, 100})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitcPredictWithGradients)
    ->ArgNames({"N", "M"})
    ->Args({5000, 100})
    ->Args({5000, 50})
    ->Args({5000, 500})
    ->Args({5000, 1000})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SsgpNlmlGradient)
    ->ArgNames({"N", "m", "threads"})
    ->Args({5000, 100, 1})
    ->Args({5000, 100, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SsgpPredictWithGradients)
    ->ArgNames({"N", "m"})
    ->Args({5000, 100})
    ->Unit(benchmark::kMicrosecond);
