// Cost of the compact backend (exact GP, Wendland phi_{D,1} kernel, CHOLMOD; compact.hpp) where the
// dense exact GP cannot go: one negative log marginal likelihood with its full gradient (analysis,
// supernodal factorisation, block Takahashi inverse subset) and one prediction of mean, variance and
// both input gradients (a sparse solve over the elimination-tree reach).
//
//  - synthetic, D = 2: N = 1000, 10000, 100000 points uniform in [0, 1]^2, targets sin(6 x1) cos(4 x2)
//    + 0.05 noise, support radii from the data-driven start (32 neighbours per point). The dense exact
//    GP would need 80 GB for one N x N matrix at N = 100,000 (the machine has 24 GB).
//  - kin40k (8 inputs): the 10,000 training points, and all 40,000 (training + test inputs pooled,
//    targets likewise) as a timing case, support from the data-driven start with 8 neighbours (in 8-D
//    the fill-in of wider supports makes the factor nearly dense; see README).
// The data file is found through $GPILQG_DATA_DIR or the repository's data/; without it
// the kin40k cases are skipped. One iteration per case (they take seconds); no flags needed:
//   build/bench/gpilqg_gp_compact_bench

#include <benchmark/benchmark.h>

#include <H5Cpp.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "gpilqg/gp/compact.hpp"

namespace {

using gpilqg::Matrix;
using gpilqg::Vector;
namespace gp = gpilqg::gp;
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

gp::TrainingSet synthetic(int n) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  gp::TrainingSet data{Matrix(n, 2), Vector(n)};
  for (int i = 0; i < n; ++i) {
    data.inputs(i, 0) = u(rng);
    data.inputs(i, 1) = u(rng);
    data.targets(i) = std::sin(6.0 * data.inputs(i, 0)) * std::cos(4.0 * data.inputs(i, 1)) + noise(rng);
  }
  return data;
}

std::filesystem::path kin40k_file() {
  const char* dir = std::getenv("GPILQG_DATA_DIR");
  const std::filesystem::path data = dir != nullptr ? dir : GPILQG_BENCH_DATA_DIR;
  return data / "gp-benchmarks" / "kin40k.h5";
}

RowMajor read(const H5::H5File& file, const char* name) {
  const H5::DataSet data = file.openDataSet(name);
  hsize_t dims[2] = {0, 1};
  data.getSpace().getSimpleExtentDims(dims);
  RowMajor values(static_cast<Eigen::Index>(dims[0]), data.getSpace().getSimpleExtentNdims() == 2 ? static_cast<Eigen::Index>(dims[1]) : 1);
  data.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  return values;
}

/// The first n of kin40k's training points followed by its test points (n <= 40,000).
gp::TrainingSet kin40k(int n) {
  const H5::H5File file(kin40k_file().c_str(), H5F_ACC_RDONLY);
  Matrix x(40000, 8);
  Vector y(40000);
  x << read(file, "X_train"), read(file, "X_test");
  y << read(file, "y_train").col(0), read(file, "y_test").col(0);
  return gp::TrainingSet{x.topRows(n), y.head(n)};
}

gp::TrainingSet make_data(int source, int n) { return source == 0 ? synthetic(n) : kin40k(n); }

gp::CompactBackend backend(int source) {
  gp::CompactOptions options;
  options.initial_neighbours = source == 0 ? 32 : 8;
  options.max_factor_nonzeros = 400'000'000;
  return gp::CompactBackend(options);
}

bool available(benchmark::State& state, int source) {
  if (source == 0 || std::filesystem::exists(kin40k_file())) return true;
  state.SkipWithError("kin40k.h5 not found (set GPILQG_DATA_DIR)");
  return false;
}

void BM_CompactNlmlGradient(benchmark::State& state) {
  const int source = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  if (!available(state, source)) return;
  const gp::TrainingSet data = make_data(source, n);
  auto objective = backend(source).objective(data, gp::FitOptions{});
  const Vector theta = objective->initial_parameters();
  Vector gradient;
  for (auto _ : state) benchmark::DoNotOptimize(objective->evaluate(theta, &gradient).value);
  state.counters["neighbour_scale_log_l0"] = theta(0);
}

void BM_CompactPrediction(benchmark::State& state) {
  const int source = static_cast<int>(state.range(0)), n = static_cast<int>(state.range(1));
  if (!available(state, source)) return;
  const gp::TrainingSet data = make_data(source, n);
  const gp::CompactBackend b = backend(source);
  const auto model = b.condition(data, b.objective(data, gp::FitOptions{})->initial_parameters());
  std::mt19937_64 rng(3);
  Matrix queries(256, data.input_dim());
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (Eigen::Index q = 0; q < queries.rows(); ++q) queries.row(q) = data.inputs.row(pick(rng)).array() + 1e-3;
  gp::Prediction p;
  Eigen::Index q = 0;
  for (auto _ : state) {
    model->predict(queries.row(q).transpose(), p, gp::PredictionRequest{true, true});
    benchmark::DoNotOptimize(p.variance);
    q = (q + 1) % queries.rows();
  }
}

// {source (0 synthetic D = 2, 1 kin40k), N}
BENCHMARK(BM_CompactNlmlGradient)
    ->Args({0, 1000})->Args({0, 10000})->Args({0, 100000})->Args({1, 10000})->Args({1, 40000})
    ->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CompactPrediction)
    ->Args({0, 1000})->Args({0, 10000})->Args({0, 100000})->Args({1, 10000})->Args({1, 40000})
    ->MinTime(0.5)->Unit(benchmark::kMicrosecond);

}  // namespace
