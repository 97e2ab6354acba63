// Cost of one belief propagation through a multi-output SE-ARD GP by exact moment matching
// (gp/moment_matching.hpp), with and without the derivatives PDDP needs, at N = 300 training points
// (and 600 for the cart-pole, the size of the main job's exact GP):
//   cart-pole  D = 5  (4 states + 1 control), E = 4 outputs  (belief dimension 4 + 10 = 14)
//   quadrotor  D = 16 (12 states + 4 controls), E = 12 outputs (belief dimension 12 + 78 = 90)
// The ...PerOutputCentres variants give every output its own N = 300 centres (FITC's case, each output
// its own pseudo-inputs): the same work as shared centres, so the figures should match.
// BM_Expm1/<kind> times the moment matching's innermost step, expm1 over one 600 x 600 pair of outputs
// (the cart-pole's exact GP), with glibc's scalar expm1 and each vector kind this processor supports.
// Run e.g. build/bench/gpilqg_moment_matching_bench --benchmark_min_time=0.5

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "gpilqg/gp/moment_matching.hpp"
#include "../gp/src/vector_expm1.hpp"

namespace {

using gpilqg::Matrix;
using gpilqg::Vector;
using namespace gpilqg::gp;

/// E GPs on N random inputs in [-2, 2]^D with smooth targets and length-scales between 0.8 and 2;
/// shared inputs, or (per_output) fresh inputs for every output.
SeArdMomentMatcher make_matcher(int n, int d, int e, bool per_output = false) {
  std::mt19937 gen(17);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  std::uniform_real_distribution<double> log_l(std::log(0.8), std::log(2.0));
  Matrix x(n, d);
  std::vector<Matrix> centres;
  std::vector<SeArdOutput> outputs;
  for (int a = 0; a < e; ++a) {
    if (a == 0 || per_output)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < d; ++j) x(i, j) = uniform(gen);
    centres.push_back(x);
    Vector y(n);
    for (int i = 0; i < n; ++i) y(i) = std::sin(x(i, a % d) + 0.3 * a) + 0.2 * x(i, (a + 1) % d) * x(i, 0);
    Vector lengthscales(d);
    for (int j = 0; j < d; ++j) lengthscales(j) = log_l(gen);
    outputs.push_back(condition_se_ard_output(x, y, lengthscales, 0.0, std::log(0.05)));
  }
  if (per_output) return SeArdMomentMatcher(std::move(centres), std::move(outputs));
  return SeArdMomentMatcher(std::move(x), std::move(outputs));
}

/// A belief with the last `controls` inputs deterministic (zero rows and columns), as in PDDP.
void propagate(benchmark::State& state, int d, int e, int controls, MomentDerivatives derivatives,
               bool per_output = false) {
  const int n = static_cast<int>(state.range(0));
  const SeArdMomentMatcher matcher = make_matcher(n, d, e, per_output);
  const Vector mu = Vector::LinSpaced(d, -0.5, 0.5);
  Matrix sigma = Matrix::Zero(d, d);
  const int states = d - controls;
  Matrix root = Matrix::Random(states, states) * 0.1;
  sigma.topLeftCorner(states, states) = root * root.transpose() + 0.01 * Matrix::Identity(states, states);
  MomentMatch out;
  matcher.propagate(mu, sigma, out, derivatives);  // warm-up: sizes the workspace
  for (auto _ : state) {
    matcher.propagate(mu, sigma, out, derivatives);
    benchmark::DoNotOptimize(out.covariance.data());
    benchmark::ClobberMemory();
  }
}

void BM_CartpoleMoments(benchmark::State& state) { propagate(state, 5, 4, 1, MomentDerivatives::None); }
void BM_CartpoleMomentsAndDerivatives(benchmark::State& state) { propagate(state, 5, 4, 1, MomentDerivatives::All); }
void BM_QuadrotorMoments(benchmark::State& state) { propagate(state, 16, 12, 4, MomentDerivatives::None); }
void BM_QuadrotorMomentsAndDerivatives(benchmark::State& state) {
  propagate(state, 16, 12, 4, MomentDerivatives::All);
}

void BM_QuadrotorMomentsPerOutputCentres(benchmark::State& state) {
  propagate(state, 16, 12, 4, MomentDerivatives::None, true);
}
void BM_QuadrotorMomentsAndDerivativesPerOutputCentres(benchmark::State& state) {
  propagate(state, 16, 12, 4, MomentDerivatives::All, true);
}

/// expm1 over 600 x 600 arguments spread like the moment matching's D (small, of both signs).
void BM_Expm1(benchmark::State& state, gpilqg::gp::detail::VectorIsa isa) {
  using namespace gpilqg::gp::detail;
  if (!supported(isa)) {
    state.SkipWithError("not supported by this processor");
    return;
  }
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> d(-0.3, 0.3);
  std::vector<double> arguments(600 * 600);
  for (double& x : arguments) x = d(gen);
  std::vector<double> values(arguments.size());
  for (auto _ : state) {
    values = arguments;
    expm1_in_place(values, isa);
    benchmark::DoNotOptimize(values.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(arguments.size()));
}

BENCHMARK_CAPTURE(BM_Expm1, scalar, gpilqg::gp::detail::VectorIsa::Scalar)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Expm1, sse2, gpilqg::gp::detail::VectorIsa::Sse2)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Expm1, avx2, gpilqg::gp::detail::VectorIsa::Avx2)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Expm1, avx512, gpilqg::gp::detail::VectorIsa::Avx512)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CartpoleMoments)->Arg(300)->Arg(600)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CartpoleMomentsAndDerivatives)->Arg(300)->Arg(600)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_QuadrotorMoments)->Arg(300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuadrotorMomentsAndDerivatives)->Arg(300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuadrotorMomentsPerOutputCentres)->Arg(300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuadrotorMomentsAndDerivativesPerOutputCentres)->Arg(300)->Unit(benchmark::kMillisecond);

}  // namespace
