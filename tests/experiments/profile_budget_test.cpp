/// `gpilqg profile`'s time budget: a row predicted over it is skipped with its reason before any fit
/// (a data set no fit accepts proves it), the compact backend's prediction comes from CHOLMOD's
/// symbolic analysis, a fit that passes the budget stops with its best point and says so, the reason
/// reaches the JSON and the HDF5 file, `--time-budget 0` disables it and bad values are refused
/// naming the option.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/compact.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

/// n training and t test points uniform in [0, 1]^d, y = sum_k sin(3 x_k) + 0.05 noise (or constant).
ProfileData synthetic(int n, int t, int d, bool constant_targets = false) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  auto draw = [&](int rows, Matrix& x, Vector& y) {
    x.resize(rows, d);
    y.resize(rows);
    for (int i = 0; i < rows; ++i) {
      for (int k = 0; k < d; ++k) x(i, k) = u(rng);
      y(i) = constant_targets ? 0.5 : (3.0 * x.row(i).array()).sin().sum() + noise(rng);
    }
  };
  ProfileData data;
  data.name = "synthetic";
  data.format = "benchmark";
  data.target = "y_train";
  draw(n, data.train.inputs, data.train.targets);
  draw(t, data.test_inputs, data.test_targets);
  return data;
}

ProfileOptions options_for(const std::string& backend, double budget, double flops_per_second) {
  ProfileOptions options;
  options.backends = {backend};
  options.sizes = {0};
  options.fit.restarts = 0;
  options.fit.max_evaluations = 100;
  options.time_budget_seconds = budget;
  options.flops_per_second = flops_per_second;
  return options;
}

TEST(ProfileBudget, ARowPredictedOverTheBudgetIsSkippedWithItsReasonAndNoFit) {
  // Constant targets: every backend refuses them when it fits (an InputError naming the file), so a
  // row that comes back skipped was never fitted.
  const ProfileData data = synthetic(60, 20, 2, true);
  for (const std::string backend : {"exact", "fitc", "ssgp"}) {
    const ProfileOptions options = options_for(backend, 1.0, 1e3);  // a machine of 1 kFLOP/s
    const ProfileRow row = run_profile_case("synthetic.h5", data, options, {backend, 60});
    EXPECT_EQ(row.status, "skipped") << backend;
    EXPECT_EQ(row.reason.rfind("predicted ", 0), 0u) << row.reason;
    EXPECT_NE(row.reason.find(" s > 1 s time budget ("), std::string::npos) << row.reason;
    EXPECT_EQ(row.evaluations, 0);
    EXPECT_EQ(row.fit_seconds, 0.0);
    // Without a time budget the same row reaches the fit, which refuses the data.
    EXPECT_THROW((void)run_profile_case("synthetic.h5", data, options_for(backend, 0.0, 1e3), {backend, 60}), InputError)
        << backend;
  }
  // The exact GP's count by hand (profile.hpp), N = 60, D = 2, T = 20, E = 1 + 100:
  //   per evaluation 60^3 + 60^2 (3 * 2 + 20) = 309,600; final 2 * 60^3 / 3 + 20 * 60^2 + 20 * 60 * 26 = 247,200;
  //   309,600 * 101 + 247,200 = 31,516,800 flops at 1e3 flops/s.
  const ProfileRow exact = run_profile_case("synthetic.h5", data, options_for("exact", 1.0, 1e3), {"exact", 60});
  EXPECT_EQ(exact.reason,
            "predicted 31,517 s > 1 s time budget (dense: 3.1e5 flops per evaluation x 101 evaluations + 2.5e5 to "
            "condition and predict, at 1e-06 GFLOP/s)");
}

TEST(ProfileBudget, EveryBackendsOwnSizesCountInTheMemoryAndTimeBudgets) {
  // Constant targets: a row that comes back skipped was never fitted (the fit would refuse them).
  const ProfileData data = synthetic(50, 20, 2, true);
  // SSGP with 4096 frequencies on 50 points: its 8192 x 8192 matrices, not N, set the cost.
  ProfileOptions ssgp = options_for("ssgp", 5.0, 1e11);
  ssgp.settings.frequencies = 4096;
  ssgp.memory_budget_bytes = 1.0 * (1ull << 30);
  EXPECT_EQ(run_profile_case("synthetic.h5", data, ssgp, {"ssgp", 50}).reason,
            "SSGP at N = 50 with 4096 frequencies needs 2.51 GiB (2 N x 2M and 5 2M x 2M matrices), over the budget "
            "of 1.00 GiB");
  ssgp.memory_budget_bytes = 4.0 * (1ull << 30);
  const ProfileRow slow = run_profile_case("synthetic.h5", data, ssgp, {"ssgp", 50});
  EXPECT_EQ(slow.status, "skipped");
  EXPECT_EQ(slow.reason.rfind("predicted ", 0), 0u) << slow.reason;  // the 8192^3 Cholesky per evaluation
  EXPECT_NE(slow.reason.find("SSGP: 1.3e12 flops per evaluation"), std::string::npos) << slow.reason;
  // FITC: 10,000 inducing points are capped at N; at N = 20,000 its M x N and M x M matrices count.
  ProfileOptions fitc = options_for("fitc", 0.0, 0.0);
  fitc.settings.inducing = 10000;
  const ProfileCase big{"fitc", 20000};
  const std::optional<RowMemory> memory = profile_row_memory(big, fitc);
  ASSERT_TRUE(memory.has_value());
  EXPECT_EQ(memory->bytes, 8.0 * (4.0 * 20000 * 10000 + 8.0 * 10000.0 * 10000));
  EXPECT_EQ(profile_row_memory({"fitc", 50}, fitc)->bytes, 8.0 * (4.0 * 50 * 50 + 8.0 * 50 * 50));
  EXPECT_FALSE(profile_row_memory({"compact", 50}, fitc).has_value());
}

TEST(ProfileBudget, TheCompactPredictionComesFromCholmodsSymbolicAnalysis) {
  const ProfileData data = synthetic(400, 30, 17);
  const ProfileOptions options = options_for("compact", 1.0, 1e6);
  const ProfileCase c{"compact", 400};
  // The count at the fit's first start, from the public analysis.
  const auto backend = gp::make_backend("compact", options.settings);
  const Vector start = backend->objective(data.train, options.fit)->initial_parameters();
  const gp::CompactFactorAnalysis a = dynamic_cast<const gp::CompactBackend&>(*backend).analyze(data.train, start);
  ASSERT_GT(a.factorisation_flops, 400.0);
  const ProfileRowWork work = profile_row_work(c, data.train, 30, options, options.fit);
  EXPECT_EQ(work.per_evaluation, a.factorisation_flops + a.inverse_subset_flops +
                                     static_cast<double>(a.kernel_nonzeros) * (6.0 * 17 + 40.0));
  EXPECT_EQ(work.final, a.factorisation_flops + 2.0 * 30 * a.factor_nonzeros);
  EXPECT_EQ(work.evaluations, 101);
  const ProfileRow row = run_profile_case("synthetic.h5", data, options, c);
  EXPECT_EQ(row.status, "skipped");
  EXPECT_NE(row.reason.find("time budget (CHOLMOD: "), std::string::npos) << row.reason;
  EXPECT_NE(row.reason.find(" flops per factorisation + "), std::string::npos) << row.reason;
  EXPECT_NE(row.reason.find(" for the gradient's inverse subset, x 101 evaluations + "), std::string::npos)
      << row.reason;
}

TEST(ProfileBudget, AFitThatPassesTheBudgetStopsWithItsBestPointAndSaysSo) {
  // N = 800: about 5e8 flops per evaluation, a few dozen milliseconds; the prediction at an assumed
  // 1e15 flops/s lets the row run, and the 0.1 s budget stops it after a few evaluations.
  const ProfileData data = synthetic(800, 50, 2);
  const ProfileRow row = run_profile_case("synthetic.h5", data, options_for("exact", 0.1, 1e15), {"exact", 800});
  ASSERT_EQ(row.status, "ok") << row.reason;
  EXPECT_EQ(row.termination, "time limit reached");
  EXPECT_EQ(row.reason, "stopped at time budget after " + std::to_string(row.evaluations) + " evaluations");
  EXPECT_GE(row.evaluations, 1);
  EXPECT_LT(row.evaluations, 100);
  EXPECT_TRUE(std::isfinite(row.smse));
  EXPECT_LT(row.fit_seconds, 2.0);
}

void write_dataset(H5::H5File& h5, const std::string& name, const Matrix& values) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = values;
  const bool vector = values.cols() == 1;
  const hsize_t dims[2] = {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())};
  h5.createDataSet(name, H5::PredType::IEEE_F64LE, H5::DataSpace(vector ? 1 : 2, dims))
      .write(row_major.data(), H5::PredType::NATIVE_DOUBLE);
}

fs::path write_benchmark(const fs::path& file, const ProfileData& data) {
  H5::H5File h5(file.c_str(), H5F_ACC_TRUNC);
  write_dataset(h5, "X_train", data.train.inputs);
  write_dataset(h5, "y_train", data.train.targets);
  write_dataset(h5, "X_test", data.test_inputs);
  write_dataset(h5, "y_test", data.test_targets);
  return file;
}

TEST(ProfileBudgetCli, TheCommandLineSkipsWithTheReasonInJsonAndHdf5AndZeroDisablesIt) {
  const fs::path dir = test::temporary_dir("profile_time_budget");
  const fs::path data = write_benchmark(dir / "tiny.h5", synthetic(60, 20, 2));
  const std::string run = "profile '" + data.string() + "' --backends exact,ssgp --frequencies 8 --max-evaluations 10 --json";
  // 1e-9 s: every row needs more than that at any machine rate (which is measured for it).
  const auto skipped = test::run_cli(run + " --time-budget 1e-9 --out '" + (dir / "out.h5").string() + "'");
  ASSERT_EQ(skipped.status, 0) << skipped.err;
  const auto report = nlohmann::json::parse(skipped.out);
  EXPECT_EQ(report["settings"]["time_budget_s"], 1e-9);
  ASSERT_EQ(report["rows"].size(), 2u);
  const H5::H5File h5((dir / "out.h5").c_str(), H5F_ACC_RDONLY);
  const H5::DataSet reasons = h5.openDataSet("rows/reason");
  std::vector<char*> stored(2);
  reasons.read(stored.data(), reasons.getStrType());
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& row = report["rows"][i];
    EXPECT_EQ(row["status"], "skipped");
    const std::string reason = row["reason"];
    EXPECT_NE(reason.find(" s time budget ("), std::string::npos) << reason;
    EXPECT_NE(reason.find(" GFLOP/s)"), std::string::npos) << reason;
    EXPECT_TRUE(row["smse"].is_null());
    EXPECT_EQ(row["evaluations"], 0);
    EXPECT_EQ(std::string(stored[i]), reason);
  }
  H5Dvlen_reclaim(reasons.getStrType().getId(), reasons.getSpace().getId(), H5P_DEFAULT, stored.data());
  // 0: no time budget; without the option: 120 s, which these tiny rows are far below.
  for (const std::string option : {" --time-budget 0", ""}) {
    const auto result = test::run_cli(run + option);
    ASSERT_EQ(result.status, 0) << result.err;
    const auto j = nlohmann::json::parse(result.out);
    EXPECT_EQ(j["settings"]["time_budget_s"], option.empty() ? 120.0 : 0.0);
    for (const auto& row : j["rows"]) EXPECT_EQ(row["status"], "ok") << row.dump();
  }
}

TEST(ProfileBudgetCli, BadTimeBudgetsAreRefusedNamingTheOption) {
  const fs::path dir = test::temporary_dir("profile_time_budget_bad");
  const fs::path data = write_benchmark(dir / "tiny.h5", synthetic(60, 20, 2));
  for (const std::string bad : {"-1", "nan", "inf", "soon"}) {
    const auto result = test::run_cli("profile '" + data.string() + "' --backends exact --time-budget " + bad);
    EXPECT_EQ(result.status, 2) << bad;
    EXPECT_NE(result.err.find("--time-budget: "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find("expected a finite number >= 0"), std::string::npos) << result.err;
    EXPECT_TRUE(result.out.empty());
  }
  // The library refuses them too, naming the option.
  ProfileOptions options = options_for("exact", -1.0, 0.0);
  const ProfileData tiny = synthetic(60, 20, 2);
  for (const double bad : {-1.0, std::nan("")}) {
    options.time_budget_seconds = bad;
    try {
      options.validate(tiny);
      ADD_FAILURE() << "expected an error for " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--time-budget: is ", 0), 0u) << e.what();
    }
  }
}

}  // namespace
}  // namespace gpilqg
