/// The full exact GP (all 7,168 points, no subsample) with the published fixed hyperparameters on
/// pumadyn-32nm reproduces the reference scores of data/gp-benchmarks/README.md to 1e-5.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <chrono>

#include "gp_test_support.hpp"
#include "gpilqg/gp/metrics.hpp"

namespace gpilqg::gp::test {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Matrix read_dataset(const H5::H5File& file, const std::string& name) {
  const H5::DataSet data = file.openDataSet(name);
  const H5::DataSpace space = data.getSpace();
  hsize_t dims[2] = {0, 1};
  space.getSimpleExtentDims(dims);
  RowMajor values(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(space.getSimpleExtentNdims() == 2 ? dims[1] : 1));
  data.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  return values;
}

double read_attribute(const H5::Group& group, const std::string& name) {
  double value = 0.0;
  group.openAttribute(name).read(H5::PredType::NATIVE_DOUBLE, &value);
  return value;
}

TEST(BenchmarkData, FullExactGpReproducesPumadynScores) {
  const auto path = data_dir() / "gp-benchmarks" / "pumadyn32nm.h5";
  const H5::H5File file(path.c_str(), H5F_ACC_RDONLY);
  TrainingSet train{read_dataset(file, "X_train"), read_dataset(file, "y_train").col(0)};
  const Matrix test_inputs = read_dataset(file, "X_test");
  const Vector test_targets = read_dataset(file, "y_test").col(0);
  const H5::Group reference = file.openGroup("reference_hyperparameters");
  Hyperparameters hyp;
  hyp.log_lengthscales = read_dataset(file, "reference_hyperparameters/log_lengthscales").col(0);
  hyp.log_signal_std = read_attribute(reference, "log_signal_std");
  hyp.log_noise_std = read_attribute(reference, "log_noise_std");
  ASSERT_EQ(train.size(), 7168);
  ASSERT_EQ(train.input_dim(), 32);
  ASSERT_EQ(test_inputs.rows(), 1024);

  const ExactGpBackend backend(ExactGpOptions{ExactGpOptions::kAllPoints, 2});  // both cores
  const auto start = std::chrono::steady_clock::now();
  const TrainingSet selected = backend.select_training_points(train, 1);
  ASSERT_EQ(selected.size(), 7168);  // "all" means all
  const auto model = backend.condition(selected, hyp.pack());
  Vector mean, variance;
  model->predict(test_inputs, mean, variance);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(model->conditioning().status, FactorStatus::Ok);
  const Vector predictive_variance = (variance.array() + model->noise_variance()).matrix();
  const RegressionScores s = regression_scores(test_targets, mean, predictive_variance, train.targets);
  EXPECT_NEAR(s.smse, 0.0443591, 1e-5 * 0.0443591);
  EXPECT_NEAR(s.mnlp, -0.15998, 1e-5 * 0.15998);
  EXPECT_NEAR(s.msll, -1.55853, 1e-5 * 1.55853);
  RecordProperty("seconds", std::to_string(seconds));
  std::printf("pumadyn-32nm exact GP N=7168: SMSE %.7g MNLP %.7g MSLL %.7g in %.2f s\n", s.smse, s.mnlp, s.msll,
              seconds);
}

}  // namespace
}  // namespace gpilqg::gp::test
