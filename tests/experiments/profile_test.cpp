/// `gpilqg profile` end to end: on a tiny benchmark-format file written here, the scores in its JSON
/// equal SMSE / MNLP / MSLL computed directly from a model conditioned with the reported parameters;
/// the HDF5 file holds the same numbers; the memory budget skips the exact GP with a reason; measurement
/// sets work with a chosen output; bad input exits 2 naming the file and dataset.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/metrics.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

using test::quote;

void write(H5::Group& group, const std::string& name, const RowMajor& values, bool vector) {
  const hsize_t dims[2] = {static_cast<hsize_t>(vector ? values.size() : values.rows()), static_cast<hsize_t>(values.cols())};
  group.createDataSet(name, H5::PredType::IEEE_F64LE, H5::DataSpace(vector ? 1 : 2, dims))
      .write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

struct Benchmark {
  gp::TrainingSet train;
  Matrix test_inputs;
  Vector test_targets;
  gp::Hyperparameters reference;
};

/// 60 training and 40 test points in [-2, 2]^2, y = sin(x1) + 0.5 cos(2 x2) + 0.1 noise.
Benchmark make_benchmark() {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  auto draw = [&](int n, Matrix& x, Vector& y) {
    x.resize(n, 2);
    y.resize(n);
    for (int i = 0; i < n; ++i) {
      x(i, 0) = u(rng);
      x(i, 1) = u(rng);
      y(i) = std::sin(x(i, 0)) + 0.5 * std::cos(2.0 * x(i, 1)) + noise(rng);
    }
  };
  Benchmark b;
  draw(60, b.train.inputs, b.train.targets);
  draw(40, b.test_inputs, b.test_targets);
  b.reference.log_lengthscales = Vector::Constant(2, std::log(0.9));
  b.reference.log_signal_std = std::log(0.8);
  b.reference.log_noise_std = std::log(0.1);
  return b;
}

fs::path write_benchmark(const fs::path& file, const Benchmark& b, bool with_test_targets = true) {
  H5::H5File h5(file.c_str(), H5F_ACC_TRUNC);
  H5::Group root = h5.openGroup("/");
  write(root, "X_train", b.train.inputs, false);
  write(root, "y_train", b.train.targets.transpose(), true);
  write(root, "X_test", b.test_inputs, false);
  if (with_test_targets) write(root, "y_test", b.test_targets.transpose(), true);
  H5::Group ref = h5.createGroup("reference_hyperparameters");
  write(ref, "log_lengthscales", b.reference.log_lengthscales.transpose(), true);
  for (const auto& [name, value] : {std::pair<std::string, double>{"log_signal_std", b.reference.log_signal_std},
                                    {"log_noise_std", b.reference.log_noise_std}})
    ref.createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(H5S_SCALAR)).write(H5::PredType::NATIVE_DOUBLE, &value);
  return file;
}

/// Scores of `backend` conditioned on all training points with `parameters`, computed here.
gp::RegressionScores direct_scores(const Benchmark& b, const std::string& backend, const Vector& parameters) {
  const auto model = gp::make_backend(backend, gp::BackendSettings{1000, 100, 100, 32, 256, 1})->condition(b.train, parameters);
  Vector mean, variance;
  model->predict(b.test_inputs, mean, variance);
  return gp::regression_scores(b.test_targets, mean, (variance.array() + model->noise_variance()).matrix(),
                               b.train.targets);
}

const nlohmann::json& row(const nlohmann::json& report, const std::string& backend, int size) {
  for (const auto& r : report["rows"])
    if (r["backend"] == backend && r["size"] == size) return r;
  throw std::runtime_error("no row " + backend + " " + std::to_string(size));
}

TEST(ProfileCli, JsonScoresEqualADirectComputationAndTheHdf5File) {
  const fs::path dir = test::temporary_dir("profile");
  const Benchmark b = make_benchmark();
  const fs::path data = write_benchmark(dir / "tiny.h5", b);
  const auto result = test::run_cli("profile " + quote(data) + " --backends exact,compact,fitc --sizes 30,all --json " +
                                    "--inducing 10 --max-evaluations 30 --out " + quote(dir / "out.h5") + " --plots " +
                                    quote(dir / "plots"));
  ASSERT_EQ(result.status, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);  // stdout holds exactly one JSON document
  EXPECT_EQ(report["data"]["test_points"], 40);
  EXPECT_EQ(report["rows"].size(), 8u);  // (exact_reference + 3 backends) x 2 sizes
  // The baseline: the exact GP with the reference hyperparameters on all 60 points.
  const auto& baseline = row(report, "exact_reference", 60);
  const gp::RegressionScores expected = direct_scores(b, "exact", b.reference.pack());
  EXPECT_NEAR(baseline["smse"].get<double>(), expected.smse, 1e-9 * expected.smse);
  EXPECT_NEAR(baseline["mnlp"].get<double>(), expected.mnlp, 1e-9 * std::abs(expected.mnlp));
  EXPECT_NEAR(baseline["msll"].get<double>(), expected.msll, 1e-9 * std::abs(expected.msll));
  // Fitted backends: the scores of a model conditioned here with the reported parameters.
  for (const std::string backend : {"exact", "compact"}) {
    const auto& r = row(report, backend, 60);
    ASSERT_EQ(r["status"], "ok") << r.dump();
    const auto p = r["parameters"].get<std::vector<double>>();
    const gp::RegressionScores s = direct_scores(b, backend, Eigen::Map<const Vector>(p.data(), static_cast<Eigen::Index>(p.size())));
    EXPECT_NEAR(r["smse"].get<double>(), s.smse, 1e-8 * s.smse) << backend;
    EXPECT_NEAR(r["mnlp"].get<double>(), s.mnlp, 1e-8 * std::abs(s.mnlp)) << backend;
    EXPECT_NEAR(r["msll"].get<double>(), s.msll, 1e-8 * std::abs(s.msll)) << backend;
    EXPECT_LT(s.smse, 0.2) << backend;  // it learned something
  }
  // The HDF5 file has the same rows, and the plot was made from it.
  const H5::H5File h5((dir / "out.h5").c_str(), H5F_ACC_RDONLY);
  const H5::DataSet smse = h5.openDataSet("rows/smse");
  std::vector<double> values(8);
  smse.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_DOUBLE_EQ(values[i], report["rows"][i]["smse"].get<double>());
  EXPECT_TRUE(fs::exists(dir / "plots" / "profile_pareto.png"));
  EXPECT_FALSE(fs::exists(dir / ("out.h5.tmp-" + std::to_string(0))));
}

TEST(ProfileCli, MemoryBudgetSkipsTheExactGpAndSaysWhy) {
  const fs::path dir = test::temporary_dir("profile_budget");
  const fs::path data = write_benchmark(dir / "tiny.h5", make_benchmark());
  // 16 * 60^2 = 57.6 kB fitted, 28.8 kB conditioned: a 40 kB budget keeps only the baseline.
  const auto result = test::run_cli("profile " + quote(data) + " --backends exact,ssgp --sizes all --json " +
                                    "--frequencies 8 --max-evaluations 10 --memory-budget-gb 3.7e-5");
  ASSERT_EQ(result.status, 0) << result.err;
  const auto report = nlohmann::json::parse(result.out);
  const auto& exact = row(report, "exact", 60);
  EXPECT_EQ(exact["status"], "skipped");
  EXPECT_NE(exact["reason"].get<std::string>().find("over the budget"), std::string::npos) << exact.dump();
  EXPECT_TRUE(exact["smse"].is_null());
  EXPECT_EQ(row(report, "exact_reference", 60)["status"], "ok");
  EXPECT_EQ(row(report, "ssgp", 60)["status"], "ok");
}

TEST(ProfileCli, MeasurementSetsWithAChosenOutput) {
  const fs::path dir = test::temporary_dir("profile_measurements");
  const IntegratedStepModel real(make_system("cartpole", Preset::RealWorld), Integrator::RK4, 0.05);
  MeasurementSet set;
  set.system = system_signature("cartpole");
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int e = 0; e < 3; ++e) {
    Episode ep;
    ep.id = e;
    ep.t = Vector::LinSpaced(40, 0.0, 39 * 0.05);
    ep.x.resize(40, 4);
    ep.u.resize(40, 1);
    Vector x = Vector::Zero(4), next(4);
    x(2) = 0.3 * e;
    for (int t = 0; t < 40; ++t) {
      ep.x.row(t) = x.transpose();
      ep.u(t, 0) = u(rng);
      real.step(x, ep.u.row(t).transpose(), next);
      x = next;
    }
    set.episodes.push_back(ep);
  }
  write_measurements_csv(dir / "cart.csv", set);
  for (const std::string target : {"residual", "increment"}) {
    const auto result = test::run_cli("profile " + quote(dir / "cart.csv") + " --system cartpole --output theta_dot --target " +
                                      target + " --backends exact --max-evaluations 20 --json");
    ASSERT_EQ(result.status, 0) << result.err;
    const auto report = nlohmann::json::parse(result.out);
    EXPECT_EQ(report["data"]["target"], target + " of theta_dot");
    EXPECT_EQ(report["data"]["test_points"], 24);  // every 5th of 117 steps
    EXPECT_EQ(report["rows"][0]["status"], "ok");
  }
  const auto missing = test::run_cli("profile " + quote(dir / "cart.csv") + " --backends exact");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("--system is required"), std::string::npos) << missing.err;
  const auto unknown = test::run_cli("profile " + quote(dir / "cart.csv") + " --system cartpole --output omega --backends exact");
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("not a state of cartpole"), std::string::npos) << unknown.err;
}

TEST(ProfileCli, BadInputExitsTwoNamingTheFileAndDataset) {
  const fs::path dir = test::temporary_dir("profile_bad");
  const Benchmark b = make_benchmark();
  const fs::path no_targets = write_benchmark(dir / "no_y_test.h5", b, false);
  auto expect_error = [](const std::string& arguments, const std::string& phrase) {
    const auto result = test::run_cli(arguments);
    EXPECT_EQ(result.status, 2) << arguments;
    EXPECT_EQ(result.err.rfind("error:", 0), 0u) << result.err;
    EXPECT_NE(result.err.find(phrase), std::string::npos) << result.err;
    EXPECT_TRUE(result.out.empty());
  };
  expect_error("profile " + quote(no_targets) + " --backends exact", "no_y_test.h5:/y_test: missing dataset");
  const fs::path good = write_benchmark(dir / "good.h5", b);
  expect_error("profile " + quote(good) + " --backends exact,gpflow", "unknown backend 'gpflow'");
  expect_error("profile " + quote(good) + " --backends exact --sizes 10,61", "--sizes: 61 is outside [1, 60]");
  expect_error("profile " + quote(good) + " --backends exact --sizes 10,ten", "entry 'ten'");
  expect_error("profile " + quote(dir / "absent.h5") + " --backends exact", "absent.h5: no such file");
}

/// A benchmark file of a few KB whose X_train declares `rows` x 3 values it never writes.
fs::path declaring_benchmark(const fs::path& file, hsize_t rows) {
  H5::H5File h5(file.c_str(), H5F_ACC_TRUNC);
  const hsize_t dims[2] = {rows, 3};
  h5.createDataSet("X_train", H5::PredType::IEEE_F64LE, H5::DataSpace(2, dims));
  return file;
}

TEST(ProfileCli, ADeclaredDatasetSizeIsRefusedBeforeAllocating) {
  const fs::path dir = test::temporary_dir("profile_declared");
  for (const hsize_t rows : {hsize_t{1} << 27, hsize_t{1} << 31}) {
    const fs::path file = declaring_benchmark(dir / "declares.h5", rows);
    const auto result = test::run_cli("profile " + quote(file) + " --backends exact");
    EXPECT_EQ(result.status, 2) << result.err;
    const std::string expected = "error: " + file.string() + ":/X_train: declares " + std::to_string(rows * 3) +
                                 " values, more than a file of " + std::to_string(fs::file_size(file)) +
                                 " bytes can hold; expected a dataset that fits the file and at most 268435456 values\n";
    EXPECT_EQ(result.err, expected);
    EXPECT_EQ(result.err.find("bad_alloc"), std::string::npos);
    EXPECT_TRUE(result.out.empty());
  }
}

TEST(ProfileCli, ABackendsRefusalOfTheDataNamesTheFile) {
  const fs::path dir = test::temporary_dir("profile_constant");
  Benchmark b = make_benchmark();
  b.train.targets.setConstant(0.25);
  const fs::path file = write_benchmark(dir / "constant.h5", b);
  const auto result = test::run_cli("profile " + quote(file) + " --backends exact");
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_EQ(result.err, "error: " + file.string() +
                            ": backend 'exact_reference', N = 60: ExactGpBackend::condition: all 60 targets equal 0.25; "
                            "expected targets that vary (a constant has nothing to regress)\n");
}

}  // namespace
}  // namespace gpilqg
