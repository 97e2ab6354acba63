/// load_fitted_gp and load_residual_model against hostile files: paths that are not readable regular
/// files of a sane size, datasets declaring more values than the file holds, array attributes where a
/// number is expected, and data the backend refuses; every error starts with the file's name.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <cmath>
#include <limits>

#include "gp_test_support.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/gp/exact_gp.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "hostile_inputs.hpp"

namespace gpilqg::gp::test {
namespace {

namespace fs = std::filesystem;

std::shared_ptr<const StepModel> cartpole_step_model() {
  return make_step_model(make_system("cartpole"), Integrator::RK4, 0.05);
}

TEST(GpIoHostileInputs, TheLoadersRefuseThemWithDataError) {
  const fs::path dir = ::gpilqg::test::temporary_dir("gp_io_hostile");
  const ExactGpBackend backend;
  ::gpilqg::test::expect_refuses_hostile_inputs<DataError>(
      "load_fitted_gp", [&](const fs::path& f) { (void)load_fitted_gp(f, "/gp", backend); },
      ::gpilqg::test::make_hostile_inputs(dir / "fitted", ".h5", kMaxDataFileBytes));
  ::gpilqg::test::expect_refuses_hostile_inputs<DataError>(
      "load_residual_model", [&](const fs::path& f) { (void)load_residual_model(f, "/model", cartpole_step_model(), backend); },
      ::gpilqg::test::make_hostile_inputs(dir / "residual", ".h5", kMaxDataFileBytes));
  fs::remove_all(dir);
}

/// A saved exact GP on the oracle data, at group /gp of `file`.
fs::path saved_gp(const fs::path& file) {
  const OracleData oracle = load_oracle();
  const ExactGpBackend backend;
  save_fitted_gp(file, "/gp", *backend.condition(oracle.train, oracle.hyp.pack()));
  return file;
}

/// What load_fitted_gp(file, "/gp") throws, as "<type>: <message>".
std::string load_error(const fs::path& file) {
  try {
    (void)load_fitted_gp(file, "/gp", ExactGpBackend{});
  } catch (const DataError& e) {
    return std::string("DataError: ") + e.what();
  } catch (const std::invalid_argument& e) {
    return std::string("invalid_argument: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("other: ") + e.what();
  }
  return "no error";
}

TEST(GpIoHostileInputs, ADeclaredDatasetSizeIsRefusedBeforeAllocating) {
  const fs::path dir = ::gpilqg::test::temporary_dir("gp_io_hostile");
  for (const hsize_t rows : {hsize_t{1} << 27, hsize_t{1} << 31}) {
    const fs::path file = saved_gp(dir / "declares.h5");
    {
      H5::H5File h5(file.c_str(), H5F_ACC_RDWR);
      h5.unlink("/gp/inputs");
      const hsize_t dims[2] = {rows, 3};
      h5.createDataSet("/gp/inputs", H5::PredType::IEEE_F64LE, H5::DataSpace(2, dims));  // never written
    }
    const std::string error = load_error(file);
    EXPECT_EQ(error.rfind("DataError: " + file.string() + ":/gp/inputs: declares " + std::to_string(rows * 3) +
                              " values, more than a file of ",
                          0),
              0u)
        << error;
  }
  fs::remove_all(dir);
}

TEST(GpIoHostileInputs, AnArrayWhereANumberIsExpectedIsRefused) {
  const fs::path dir = ::gpilqg::test::temporary_dir("gp_io_hostile");
  const fs::path file = saved_gp(dir / "array.h5");
  {
    H5::H5File h5(file.c_str(), H5F_ACC_RDWR);
    H5::Group group = h5.openGroup("/gp");
    group.removeAttr("input_dim");
    const std::vector<int> values(1000, 3);
    const hsize_t dims[1] = {values.size()};
    group.createAttribute("input_dim", H5::PredType::STD_I32LE, H5::DataSpace(1, dims))
        .write(H5::PredType::NATIVE_INT, values.data());
  }
  EXPECT_EQ(load_error(file), "DataError: " + file.string() +
                                  ":/gp attribute 'input_dim': holds 1000 values; expected a single number");
  fs::remove_all(dir);
}

TEST(GpIoHostileInputs, TheBackendsRefusalOfTheDataNamesTheFile) {
  const fs::path dir = ::gpilqg::test::temporary_dir("gp_io_hostile");
  const fs::path file = saved_gp(dir / "nan.h5");
  {
    H5::H5File h5(file.c_str(), H5F_ACC_RDWR);
    H5::DataSet parameters = h5.openDataSet("/gp/parameters");
    std::vector<double> values(static_cast<std::size_t>(parameters.getSpace().getSimpleExtentNpoints()));
    parameters.read(values.data(), H5::PredType::NATIVE_DOUBLE);
    values[0] = std::numeric_limits<double>::quiet_NaN();
    parameters.write(values.data(), H5::PredType::NATIVE_DOUBLE);
  }
  const std::string error = load_error(file);
  EXPECT_EQ(error.rfind("invalid_argument: " + file.string() + ":/gp: ", 0), 0u) << error;
  EXPECT_NE(error.find("nan"), std::string::npos) << error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg::gp::test
