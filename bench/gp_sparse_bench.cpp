// Cost of the sparse GP backends' units of work: one negative log marginal likelihood with its full
// analytic gradient (what every optimiser iteration pays), a whole fit, and one prediction of mean
// and variance with their gradients w.r.t. the test input (what every DDP step pays per output).
// D = 5, synthetic data with a fixed seed.
//
//  - N sweep 300, 1000, 5000, 20000, 100000 at M = m = 100 (NLML + gradient and prediction);
//    references at N = 5000: GPML 4.2 in Octave, 0.058 s per FITC NLML + gradient; ssgpr.m, 0.024 s.
//  - M / m sweep 50, 100, 200, 500, 1000 at N = 5000.
//  - A whole fit at N = 5000, M = m = 100: one start (the data-driven initial values, no restarts),
//    capped at kFitEvaluations = 100 NLML + gradient evaluations (FitOptions::max_evaluations).
//    FITC's includes the k-means++ initialisation of the pseudo-inputs, SSGP's the 50 draws of W
//    it tries at the start.
// Run times are fixed in the code (MinTime / Iterations / Repetitions), so no flags are needed:
//   build/bench/gpilqg_gp_sparse_bench
// The cheap cases run 3 repetitions and report, besides the built-in aggregates, "min" (best of 3).
// (FitcLikelihood / SsgpLikelihood directly for the NLML; fits through GpBackend::fit; predictions
// through FittedGp::predict.)

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "gpilqg/gp/fitc.hpp"
#include "gpilqg/gp/ssgp.hpp"

namespace {

using gpilqg::Matrix;
using gpilqg::Vector;
namespace gp = gpilqg::gp;

constexpr int kD = 5;
constexpr int kFitEvaluations = 100;

/// Best of the repetitions (the built-in aggregates are mean, median, stddev and cv).
double minimum(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

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
  const auto workspace = likelihood.make_workspace();
  for (auto _ : state) {
    const gp::NlmlEvaluation e = likelihood.evaluate(theta, &gradient, *workspace);
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
  const auto workspace = likelihood.make_workspace();
  for (auto _ : state) benchmark::DoNotOptimize(likelihood.evaluate(theta, nullptr, *workspace).value);
}

void BM_SsgpNlmlGradient(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const int m = static_cast<int>(state.range(1));
  const int threads = static_cast<int>(state.range(2));
  const gp::TrainingSet data = make_data(N);
  const gp::SsgpLikelihood likelihood(data.inputs, data.targets, m, {}, threads);
  const Vector theta = ssgp_theta(m);
  Vector gradient;
  const auto workspace = likelihood.make_workspace();
  for (auto _ : state) {
    const gp::NlmlEvaluation e = likelihood.evaluate(theta, &gradient, *workspace);
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

/// One start, at most kFitEvaluations evaluations; counters: evaluations used, NLML before and after.
void fit_loop(benchmark::State& state, const gp::GpBackend& backend, const gp::TrainingSet& data) {
  gp::FitOptions options;
  options.restarts = 0;
  options.max_evaluations = kFitEvaluations;
  gp::FitSummary summary;
  for (auto _ : state) {
    const gp::FitResult fit = backend.fit(data, options);
    summary = fit.summary;
    benchmark::DoNotOptimize(fit.model.get());
  }
  state.counters["evaluations"] = summary.evaluations;
  state.counters["nlml_start"] = summary.initial_nlml;
  state.counters["nlml_end"] = summary.nlml;
}

void BM_FitcWholeFit(benchmark::State& state) {
  const gp::TrainingSet data = make_data(static_cast<int>(state.range(0)));
  gp::FitcOptions options;
  options.inducing = static_cast<int>(state.range(1));
  fit_loop(state, gp::FitcBackend(options), data);
}

void BM_SsgpWholeFit(benchmark::State& state) {
  const gp::TrainingSet data = make_data(static_cast<int>(state.range(0)));
  gp::SsgpOptions options;
  options.frequencies = static_cast<int>(state.range(1));
  fit_loop(state, gp::SsgpBackend(options), data);
}

/// N sweep at M = 100 (threads = 1), M sweep at N = 5000, and threads = 2 at N = 5000, 100000.
void nlml_arguments(benchmark::internal::Benchmark* b) {
  for (const int N : {300, 1000, 5000, 20000, 100000}) b->Args({N, 100, 1});
  for (const int M : {50, 200, 500, 1000}) b->Args({5000, M, 1});
  b->Args({5000, 100, 2});
  b->Args({100000, 100, 2});
}

void predict_arguments(benchmark::internal::Benchmark* b) {
  for (const int N : {300, 1000, 5000, 20000, 100000}) b->Args({N, 100});
  for (const int M : {50, 200, 500, 1000}) b->Args({5000, M});
}

}  // namespace

// Wall-clock time (UseRealTime): with threads = 2 the CPU time of the calling thread alone would
// understate the cost.
BENCHMARK(BM_FitcNlmlGradient)
    ->ArgNames({"N", "M", "threads"})
    ->Apply(nlml_arguments)
    ->MinTime(0.3)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitcNlmlOnly)
    ->ArgNames({"N", "M"})
    ->Args({5000, 100})
    ->MinTime(0.3)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitcWholeFit)->ArgNames({"N", "M"})->Args({5000, 100})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitcPredictWithGradients)
    ->ArgNames({"N", "M"})
    ->Apply(predict_arguments)
    ->MinTime(0.2)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SsgpNlmlGradient)
    ->ArgNames({"N", "m", "threads"})
    ->Apply(nlml_arguments)
    ->MinTime(0.3)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SsgpWholeFit)->ArgNames({"N", "m"})->Args({5000, 100})->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SsgpPredictWithGradients)
    ->ArgNames({"N", "m"})
    ->Apply(predict_arguments)
    ->MinTime(0.2)
    ->Repetitions(3)
    ->ComputeStatistics("min", minimum)
    ->Unit(benchmark::kMicrosecond);
