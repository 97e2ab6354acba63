/// Reading the data of `gpilqg profile`: the benchmark format or a measurement set (profile.hpp).

#include <H5Cpp.h>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "gpilqg/core/dataset_size.hpp"
#include "gpilqg/core/hdf5_self_contained.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/cli_errors.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/gp/residual_model.hpp"

namespace gpilqg {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& object, const std::string& problem) {
  throw InputError(fmt::format("{}:{}: {}", file.string(), object, problem));
}

/// An open benchmark file: the HDF5 file, its path and its size in bytes (what declared dataset sizes
/// are checked against, dataset_size.hpp).
struct BenchmarkFile {
  const H5::H5File& h5;
  const std::filesystem::path& file;
  std::uintmax_t bytes = 0;
};

/// Refuses a dataset or attribute that declares more values than the file can hold or than
/// kMaxDatasetValues, before anything is allocated for it.
void check_declared_size(const BenchmarkFile& in, const std::string& object, hid_t id) {
  std::optional<std::string> problem;
  try {
    problem = hdf5_size_problem(id, in.bytes);
  } catch (const std::runtime_error& e) {
    fail(in.file, object, e.what());
  }
  if (problem)
    fail(in.file, object,
         fmt::format("{}; expected a dataset that fits the file and at most {} values", *problem, kMaxDatasetValues));
}

/// A float dataset of rank `rank` (1 or 2) as a matrix (a vector as one column).
Matrix read_dataset(const BenchmarkFile& in, const std::string& name, int rank) {
  const H5::H5File& h5 = in.h5;
  const std::filesystem::path& file = in.file;
  if (!h5.nameExists(name)) fail(file, "/" + name, "missing dataset; expected the benchmark format (X_train, y_train, X_test, y_test)");
  try {
    const H5::DataSet data = h5.openDataSet(name);
    if (data.getTypeClass() != H5T_FLOAT) fail(file, "/" + name, "is not a floating-point dataset");
    const H5::DataSpace space = data.getSpace();
    if (space.getSimpleExtentNdims() != rank)
      fail(file, "/" + name, fmt::format("has rank {}; expected {}", space.getSimpleExtentNdims(), rank));
    check_declared_size(in, "/" + name, data.getId());
    hsize_t dims[2] = {0, 1};
    space.getSimpleExtentDims(dims);
    RowMajor values(static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(rank == 2 ? dims[1] : 1));
    if (values.size() > 0) data.read(values.data(), H5::PredType::NATIVE_DOUBLE);
    for (Eigen::Index i = 0; i < values.rows(); ++i)
      for (Eigen::Index j = 0; j < values.cols(); ++j)
        if (!std::isfinite(values(i, j)))
          fail(file, "/" + name, fmt::format("entry ({}, {}) is {}; expected finite values", i, j, values(i, j)));
    return values;
  } catch (const H5::Exception& e) {
    fail(file, "/" + name, "cannot be read (HDF5: " + e.getDetailMsg() + ")");
  }
}

double read_double_attribute(const H5::Group& group, const std::filesystem::path& file, const std::string& object,
                             const std::string& name) {
  if (!group.attrExists(name)) fail(file, object + " attribute '" + name + "'", "missing");
  const H5::Attribute attribute = group.openAttribute(name);
  if (attribute.getSpace().getSimpleExtentNpoints() != 1)
    fail(file, object + " attribute '" + name + "'",
         fmt::format("holds {} values; expected a single number", attribute.getSpace().getSimpleExtentNpoints()));
  double value = 0.0;
  attribute.read(H5::PredType::NATIVE_DOUBLE, &value);
  if (!std::isfinite(value)) fail(file, object + " attribute '" + name + "'", "is not finite");
  return value;
}

ProfileData read_benchmark(const BenchmarkFile& in) {
  const H5::H5File& h5 = in.h5;
  const std::filesystem::path& file = in.file;
  ProfileData data;
  data.format = "benchmark";
  data.target = "y_train";
  data.name = file.stem().string();
  if (h5.attrExists("name")) {
    const H5::Attribute a = h5.openAttribute("name");
    check_declared_size(in, "/ attribute 'name'", a.getId());
    a.read(a.getStrType(), data.name);
  }
  data.train.inputs = read_dataset(in, "X_train", 2);
  data.train.targets = read_dataset(in, "y_train", 1).col(0);
  data.test_inputs = read_dataset(in, "X_test", 2);
  data.test_targets = read_dataset(in, "y_test", 1).col(0);
  const auto n = data.train.inputs.rows(), d = data.train.inputs.cols();
  if (data.train.targets.size() != n)
    fail(file, "/y_train", fmt::format("has {} entries; expected {} (the rows of X_train)", data.train.targets.size(), n));
  if (data.test_inputs.cols() != d)
    fail(file, "/X_test", fmt::format("has {} columns; expected {} (the columns of X_train)", data.test_inputs.cols(), d));
  if (data.test_targets.size() != data.test_inputs.rows())
    fail(file, "/y_test", fmt::format("has {} entries; expected {} (the rows of X_test)", data.test_targets.size(),
                                      data.test_inputs.rows()));
  if (n < 2 || data.test_inputs.rows() < 1) fail(file, "/X_train", "needs at least 2 training and 1 test point");
  if (h5.nameExists("reference_hyperparameters")) {
    const std::string object = "/reference_hyperparameters";
    const H5::Group group = h5.openGroup("reference_hyperparameters");
    gp::Hyperparameters h;
    h.log_lengthscales = read_dataset(in, "reference_hyperparameters/log_lengthscales", 1).col(0);
    if (h.log_lengthscales.size() != d)
      fail(file, object + "/log_lengthscales", fmt::format("has {} entries; expected D = {}", h.log_lengthscales.size(), d));
    h.log_signal_std = read_double_attribute(group, file, object, "log_signal_std");
    h.log_noise_std = read_double_attribute(group, file, object, "log_noise_std");
    data.reference = h;
  }
  return data;
}

ProfileData read_measurement_profile(const std::filesystem::path& file, const ProfileDataOptions& options) {
  if (options.system.empty())
    throw InputError(file.string() + ": a measurement set; --system is required to read it (" +
                     fmt::format("{}", fmt::join(system_names(), ", ")) + ")");
  const SystemSignature signature = system_signature(options.system);
  const MeasurementSet set = read_measurements(file, signature);
  int output = 0;
  if (!options.output.empty()) {
    const auto it = std::find_if(signature.states.begin(), signature.states.end(),
                                 [&](const auto& q) { return q.name == options.output; });
    if (it == signature.states.end()) {
      std::vector<std::string> names;
      for (const auto& q : signature.states) names.push_back(q.name);
      throw InputError(fmt::format("--output '{}': not a state of {} (states: {})", options.output, options.system,
                                   fmt::join(names, ", ")));
    }
    output = static_cast<int>(it - signature.states.begin());
  }
  double dt = 0.0;
  for (const Episode& e : set.episodes)
    if (e.length() > 1) dt = e.dt();
  if (!(dt > 0.0)) throw DataError(file, "", "no episode has two samples", "at least one step t -> t+1");
  const auto simulator_model = make_step_model(make_system(options.system, Preset::Simulator), Integrator::RK4, dt);
  const StepModel& simulator = *simulator_model;
  gp::ResidualData residual;
  try {
    residual = gp::make_residual_data(simulator, set);
  } catch (const std::invalid_argument& e) {
    throw DataError(file, "", e.what(), "one dt in all episodes");
  }
  Vector targets = residual.residuals.col(output);
  const int n = static_cast<int>(signature.states.size());
  if (options.target == ProfileTarget::Increment) {
    // x' - x = (x' - phi_sim(x, u)) + (phi_sim(x, u) - x): recover x' - x from the rows themselves.
    Vector x_next_minus_x(residual.size());
    Vector predicted(n);
    const auto workspace = simulator.make_workspace();
    for (int t = 0; t < residual.size(); ++t) {
      simulator.step(residual.inputs.row(t).head(n).transpose(), residual.inputs.row(t).tail(residual.inputs.cols() - n).transpose(),
                     predicted, nullptr, *workspace);
      x_next_minus_x(t) = targets(t) + predicted(output) - residual.inputs(t, output);
    }
    targets = x_next_minus_x;
  }
  if (options.test_every < 2)
    throw std::invalid_argument(fmt::format("test_every is {}; expected >= 2 (every k-th sample is a test sample)", options.test_every));
  const int k = options.test_every;
  std::vector<int> train_rows, test_rows;
  for (int t = 0; t < residual.size(); ++t) (t % k == 0 ? test_rows : train_rows).push_back(t);
  if (train_rows.size() < 2 || test_rows.empty())
    throw DataError(file, "", fmt::format("only {} samples", residual.size()), "enough steps for a training and a test set");
  ProfileData data;
  data.format = "measurements";
  data.name = file.stem().string();
  data.target = (options.target == ProfileTarget::Residual ? "residual of " : "increment of ") +
                signature.states[static_cast<std::size_t>(output)].name;
  auto take = [&](const std::vector<int>& rows, Matrix& inputs, Vector& y) {
    inputs.resize(static_cast<Eigen::Index>(rows.size()), residual.inputs.cols());
    y.resize(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t r = 0; r < rows.size(); ++r) {
      inputs.row(static_cast<Eigen::Index>(r)) = residual.inputs.row(rows[r]);
      y(static_cast<Eigen::Index>(r)) = targets(rows[r]);
    }
  };
  take(train_rows, data.train.inputs, data.train.targets);
  take(test_rows, data.test_inputs, data.test_targets);
  return data;
}

bool has_extension(const std::filesystem::path& file, std::initializer_list<const char*> extensions) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return std::any_of(extensions.begin(), extensions.end(), [&](const char* e) { return ext == e; });
}

}  // namespace

ProfileData read_profile_data(const std::filesystem::path& file, const ProfileDataOptions& options) {
  const std::uintmax_t bytes =
      check_input_file_as<InputError>(file, kMaxDataFileBytes, "a benchmark set or a measurement set");
  if (has_extension(file, {".csv"})) return read_measurement_profile(file, options);
  if (!has_extension(file, {".h5", ".hdf5"}))
    throw InputError(file.string() + ": unknown extension; expected .h5 / .hdf5 (benchmark or measurements) or .csv");
  H5::Exception::dontPrint();
  bool benchmark = false;
  try {
    const H5::H5File h5(file.c_str(), H5F_ACC_RDONLY);
    check_hdf5_self_contained(file, h5.getId());
    benchmark = h5.nameExists("X_train");
    if (benchmark) return read_benchmark(BenchmarkFile{h5, file, bytes});
    if (!h5.nameExists("episodes"))
      fail(file, "/", "neither X_train (benchmark format) nor /episodes (measurement set) is present");
  } catch (const H5::Exception& e) {
    throw InputError(file.string() + ": cannot be read as HDF5 (" + e.getDetailMsg() + ")");
  }
  return read_measurement_profile(file, options);
}

}  // namespace gpilqg
