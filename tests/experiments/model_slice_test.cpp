/// model_slice on a model whose answer is known: the real world differs from the simulator only in
/// the second state, by a residual of the first state alone, so the slice must show that output
/// along that input, through a measured point, over the data plus kSliceMargin length-scales, with
/// only measurements within one length-scale in the other inputs; and it is written and read back
/// with the layout of model_slice_io.hpp.

#include "gpilqg/experiments/model_slice.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/experiments/model_slice_io.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/residual_model.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

constexpr double kSliceDt = 0.1;

/// x' = x + dt (A x + B u) with two states and one control; the real world adds
/// dt 0.8 sin(2 x_0) to x'_1.
class TwoStateSystem final : public StepModel {
 public:
  explicit TwoStateSystem(bool real) : real_(real) {}
  int state_dim() const override { return 2; }
  int control_dim() const override { return 1; }
  double dt() const override { return kSliceDt; }
  using StepModel::step;
  void step(const VectorCRef& x, const VectorCRef& u, VectorRef x_next, StepJacobians*, StepWorkspace&) const override {
    x_next(0) = x(0) + kSliceDt * x(1);
    x_next(1) = x(1) + kSliceDt * (-0.5 * x(1) + u(0));
    if (real_) x_next(1) += kSliceDt * residual(x(0));
  }
  static double residual(double x0) { return 0.8 * std::sin(2.0 * x0); }

 private:
  bool real_;
};

class KnownSlice : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulator_ = std::make_shared<const TwoStateSystem>(false);
    std::mt19937_64 gen(3);
    std::uniform_real_distribution<double> x0(-2.0, 2.0), other(-1.0, 1.0);
    std::normal_distribution<double> noise(0.0, 0.005);
    constexpr int kRows = 150;
    data_.x.resize(kRows, 2), data_.u.resize(kRows, 1), data_.x_next.resize(kRows, 2);
    data_.iteration.assign(kRows, 0);
    Vector next(2);
    for (int r = 0; r < kRows; ++r) {
      data_.x.row(r) << x0(gen), other(gen);
      data_.u(r, 0) = other(gen);
      real_.step(data_.x.row(r).transpose(), data_.u.row(r).transpose(), next, nullptr);
      data_.x_next.row(r) = next.transpose() + Vector::NullaryExpr(2, [&] { return noise(gen); }).transpose();
    }
    gp::ResidualModelOptions options;
    options.fit.restarts = 1;
    model_ = std::make_unique<gp::ResidualModel>(gp::ResidualModel::fit(
        simulator_, gp::make_residual_data(*simulator_, data_.x, data_.u, data_.x_next), gp::ExactGpBackend{}, options));
    slice_ = model_slice(real_, *model_, data_);
  }
  static void TearDownTestSuite() { model_.reset(); }

  /// sum over the inputs but the slice's of ((z_k - z*_k) / l_k)^2 for row r.
  static double other_distance2(int r, const Vector& base) {
    Vector z(3);
    z << data_.x.row(r).transpose(), data_.u(r, 0);
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k)
      if (k != slice_.input) d2 += std::pow((z(k) - base(k)) / slice_.length_scales(k), 2);
    return d2;
  }
  static Vector input_row(int r) {
    Vector z(3);
    z << data_.x.row(r).transpose(), data_.u(r, 0);
    return z;
  }

  static inline const TwoStateSystem real_{true};
  static inline std::shared_ptr<const TwoStateSystem> simulator_;
  static inline TransitionData data_;
  static inline std::unique_ptr<gp::ResidualModel> model_;
  static inline ModelSlice slice_;
};

TEST_F(KnownSlice, ShowsTheCorrectedOutputAlongTheInputItDependsOn) {
  EXPECT_EQ(slice_.output, 1);  // x_0 carries no residual: its GP's signal variance is the noise's
  EXPECT_EQ(slice_.input, 0);
  ASSERT_EQ(slice_.length_scales.size(), 3);
  // The other inputs do not matter: the GP forgets them slowly.
  EXPECT_GT(slice_.length_scales(1), 3.0 * slice_.length_scales(0));
  EXPECT_GT(slice_.length_scales(2), 3.0 * slice_.length_scales(0));
}

TEST_F(KnownSlice, GoesThroughTheMeasuredPointWithTheMostMeasurementsNearIt) {
  int base_row = -1, most = -1;
  for (int c = 0; c < data_.size(); ++c) {
    int count = 0;
    for (int r = 0; r < data_.size(); ++r) count += other_distance2(r, input_row(c)) <= 1.0 ? 1 : 0;
    if ((input_row(c) - slice_.base).norm() == 0.0) base_row = c;
    most = std::max(most, count);
  }
  ASSERT_GE(base_row, 0) << "the base point is not a measured input";
  int drawn = 0;
  for (int r = 0; r < data_.size(); ++r) drawn += other_distance2(r, slice_.base) <= 1.0 ? 1 : 0;
  EXPECT_EQ(drawn, most);
  EXPECT_EQ(slice_.data_z.size(), drawn);
}

TEST_F(KnownSlice, SpansTheDataPlusAFewLengthScales) {
  const double l = slice_.length_scales(slice_.input);
  const double lo = data_.x.col(0).minCoeff(), hi = data_.x.col(0).maxCoeff();
  EXPECT_NEAR(slice_.grid(0), lo - kSliceMargin * l, 1e-12);
  EXPECT_NEAR(slice_.grid(slice_.grid.size() - 1), hi + kSliceMargin * l, 1e-12);
  // Far from the data the model is the simulator with the prior's uncertainty ...
  const double sf = std::sqrt(model_->output(1).prior_variance());
  for (const Eigen::Index end : {Eigen::Index{0}, slice_.grid.size() - 1}) {
    EXPECT_NEAR(slice_.mean(end), slice_.simulator(end), 0.02 * sf);
    EXPECT_NEAR(slice_.std(end), sf, 0.02 * sf);
  }
  // ... and over the data it is the real world, within its band.
  for (Eigen::Index p = 0; p < slice_.grid.size(); ++p) {
    if (slice_.grid(p) < lo || slice_.grid(p) > hi) continue;
    EXPECT_NEAR(slice_.mean(p), slice_.truth(p), 3.0 * slice_.std(p) + 0.01) << "at " << slice_.grid(p);
    EXPECT_LT(slice_.std(p), 0.2 * sf);
  }
}

TEST_F(KnownSlice, DrawsOnlyMeasurementsWithinOneLengthScaleWithTheirResiduals) {
  ASSERT_GT(slice_.data_z.size(), 10);
  int matched = 0;
  for (int r = 0; r < data_.size(); ++r) {
    if (other_distance2(r, slice_.base) > 1.0) continue;
    const Eigen::Index i = matched++;
    ASSERT_LT(i, slice_.data_z.size());
    EXPECT_EQ(slice_.data_z(i), data_.x(r, 0));
    EXPECT_EQ(slice_.data_y(i), data_.x_next(r, 1));
    // The measured residual is the known one plus the measurement noise (std 0.005).
    EXPECT_NEAR(slice_.data_residual(i), kSliceDt * TwoStateSystem::residual(data_.x(r, 0)), 0.025);
  }
  EXPECT_EQ(matched, slice_.data_z.size());
}

TEST_F(KnownSlice, RejectsDataOfOtherDimensions) {
  TransitionData empty;
  EXPECT_THROW(model_slice(real_, *model_, empty), std::invalid_argument);
  TransitionData wrong = data_;
  wrong.u = Matrix::Zero(data_.size(), 2);
  EXPECT_THROW(model_slice(real_, *model_, wrong), std::invalid_argument);
  EXPECT_THROW(model_slice(real_, real_, data_), std::invalid_argument);  // not a residual model
}

TEST_F(KnownSlice, IsWrittenWithItsNamesUnitsAndResiduals) {
  const auto file = test::temporary_dir("model_slice_io") / "slice.h5";
  {
    Hdf5Writer h5(file);
    const SystemSignature signature{"two_state", {{"p", "m"}, {"v", "m/s"}}, {{"f", "N"}}};
    write_model_slice(h5, "/task", slice_, signature);
    h5.close();
  }
  const Hdf5Reader h5(file);
  const std::string group = "/task/figure1";
  EXPECT_EQ(h5.string_attribute(group, "output"), "v");
  EXPECT_EQ(h5.string_attribute(group, "output_unit"), "m/s");
  EXPECT_EQ(h5.string_attribute(group, "input"), "p");
  EXPECT_EQ(h5.string_attribute(group, "input_unit"), "m");
  EXPECT_EQ(h5.read_vector(group + "/data_residual"), slice_.data_residual);
  EXPECT_EQ(h5.read_vector(group + "/length_scales"), slice_.length_scales);
  EXPECT_EQ(h5.read_vector(group + "/grid"), slice_.grid);

  ModelSlice bad = slice_;
  bad.output = 2;
  Hdf5Writer other(file.parent_path() / "bad.h5");
  EXPECT_THROW(write_model_slice(other, "/task", bad, SystemSignature{"two_state", {{"p", "m"}, {"v", "m/s"}}, {{"f", "N"}}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gpilqg
