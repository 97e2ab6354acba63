/// Every reader of core against hostile inputs: a FIFO, /dev/zero, a directory, a loop of symbolic
/// links, a missing file and an oversized (sparse) file are refused promptly, before anything is read,
/// with the reader's exception and a message naming the path (input_file.hpp); HDF5 datasets that
/// declare more values than the file can hold are refused before the allocation (dataset_size.hpp);
/// a CSV header of 200000 columns is refused quickly with a short message.

#include <gtest/gtest.h>

#include <H5Cpp.h>

#include <fstream>
#include <stdexcept>

#include "gpilqg/core/dataset_size.hpp"
#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/mujoco_system.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "gpilqg/core/systems.hpp"
#include "hostile_inputs.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

TEST(HostileInputs, EveryDataReaderRefusesThemWithDataError) {
  const std::vector<test::Reader> readers = {
      {"read_measurements (CSV)", ".csv", kMaxDataFileBytes, [](const fs::path& f) { read_measurements(f, test::cartpole_signature()); }},
      {"read_measurements (HDF5)", ".h5", kMaxDataFileBytes, [](const fs::path& f) { read_measurements(f, test::cartpole_signature()); }},
      {"read_raw_log (CSV)", ".csv", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log(f); }},
      {"read_raw_log (MAT)", ".mat", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log(f); }},
      {"read_raw_log (HDF5)", ".h5", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log(f); }},
      {"read_raw_log_csv", ".csv", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log_csv(f); }},
      {"read_raw_log_mat", ".mat", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log_mat(f); }},
      {"read_raw_log_hdf5", ".h5", kMaxDataFileBytes, [](const fs::path& f) { read_raw_log_hdf5(f); }},
      {"Hdf5Reader", ".h5", kMaxDataFileBytes, [](const fs::path& f) { Hdf5Reader reader(f); }},
  };
  test::expect_readers_refuse_hostile_inputs<DataError>(readers, test::temporary_dir("hostile"));
}

TEST(HostileInputs, TheMujocoModelLoaderRefusesThemWithInvalidArgument) {
  const fs::path dir = test::temporary_dir("hostile");
  const auto inputs = test::make_hostile_inputs(dir, ".xml", kMaxConfigFileBytes);
  test::expect_refuses_hostile_inputs<std::invalid_argument>(
      "MujocoSystem::load", [](const fs::path& f) { MujocoSystem::load(f.string()); }, inputs);
  fs::remove_all(dir);
}

TEST(HostileInputs, TheMessagesNameTheKindOfFileAndTheLimit) {
  const fs::path dir = test::temporary_dir("hostile");
  const auto inputs = test::make_hostile_inputs(dir, ".csv", kMaxDataFileBytes);
  const auto message = [&](const std::string& name) {
    for (const auto& input : inputs)
      if (input.name == name) {
        const auto issue = input_file_issue(input.path, kMaxDataFileBytes, "a measurement file");
        return issue ? issue->message(input.path) : std::string("no issue");
      }
    return std::string("no such input");
  };
  const std::string d = dir.string() + "/";
  EXPECT_EQ(message("fifo"), d + "fifo.csv: is a FIFO (named pipe), not a regular file; expected a measurement file");
  EXPECT_EQ(message("link to /dev/zero"),
            d + "zero.csv: is a character device, not a regular file; expected a measurement file");
  EXPECT_EQ(message("directory"), d + "folder.csv: is a folder, not a regular file; expected a measurement file");
  EXPECT_EQ(message("symbolic link loop"), d + "loop.csv: too many levels of symbolic links (a loop of symbolic "
                                               "links); expected a measurement file");
  EXPECT_EQ(message("missing file"), d + "missing.csv: no such file; expected a measurement file");
  EXPECT_EQ(message("oversized sparse file"),
            d + "huge.csv: is 4294967297 bytes, more than the limit of 4294967296 (4 GiB); expected a measurement "
                "file of at most 4 GiB");
  EXPECT_EQ(input_file_issue("/dev/zero", kMaxDataFileBytes, "a log file")->problem,
            "is a character device, not a regular file");
  std::ofstream(dir / "fine.csv") << "x\n";
  std::uintmax_t bytes = 0;
  EXPECT_FALSE(input_file_issue(dir / "fine.csv", kMaxDataFileBytes, "a measurement file", &bytes));
  EXPECT_EQ(bytes, 2u);
  fs::remove_all(dir);
}

TEST(DatasetSize, RefusesWhatTheFileCannotHoldAndWhatIsOverTheLimit) {
  // (a) the file's bytes: 4096 bytes hold 512 float64 values, 1100 times more when compressed.
  EXPECT_FALSE(declared_size_problem({{512}, 8, false}, 4096));
  EXPECT_EQ(declared_size_problem({{513}, 8, false}, 4096), "declares 513 values, more than a file of 4096 bytes can hold");
  EXPECT_EQ(declared_size_problem({{std::uint64_t{1} << 27, 3}, 8, false}, 4096),
            "declares 402653184 values, more than a file of 4096 bytes can hold");
  EXPECT_FALSE(declared_size_problem({{512 * 1100}, 8, true}, 4096));
  EXPECT_TRUE(declared_size_problem({{512 * 1100 + 1}, 8, true}, 4096));
  EXPECT_FALSE(declared_size_problem({{4096}, 1, false}, 4096));  // int8: one value per byte
  // (b) the fixed limit, whatever the file's size.
  const std::uintmax_t big_file = std::uintmax_t{64} << 30;
  EXPECT_FALSE(declared_size_problem({{kMaxDatasetValues}, 8, false}, big_file));
  EXPECT_EQ(declared_size_problem({{kMaxDatasetValues + 1}, 8, false}, big_file),
            "declares 268435457 values, more than the limit of 268435456 values per dataset");
  // Shapes whose product overflows 64 bits, empty shapes and scalars.
  EXPECT_EQ(declared_size_problem({{std::uint64_t{1} << 40, std::uint64_t{1} << 40}, 8, true}, big_file),
            "declares more than 18446744073709551615 values, more than a file of 68719476736 bytes can hold");
  EXPECT_FALSE(declared_size_problem({{0, std::uint64_t{1} << 62}, 8, false}, 0));
  EXPECT_FALSE(declared_size_problem({{}, 8, false}, 8));
}

/// A file of about 2 KB declaring a float64 dataset of shape `dims` that it never writes.
fs::path declaring_file(const fs::path& file, const std::string& dataset, const std::vector<hsize_t>& dims) {
  H5::H5File h5(file.c_str(), H5F_ACC_TRUNC);
  h5.createDataSet(dataset, H5::PredType::IEEE_F64LE, H5::DataSpace(static_cast<int>(dims.size()), dims.data()));
  return file;
}

TEST(DatasetSize, Hdf5ReaderRefusesADeclaredSizeBeforeAllocating) {
  const fs::path dir = test::temporary_dir("hostile");
  for (const hsize_t rows : {hsize_t{1} << 27, hsize_t{1} << 31}) {
    const fs::path file = declaring_file(dir / "declares.h5", "big", {rows, 3});
    const Hdf5Reader h5(file);
    try {
      h5.read_matrix("/big");
      ADD_FAILURE() << "accepted " << rows << " x 3";
    } catch (const DataError& e) {
      const std::string expected = file.string() + ":/big: declares " + std::to_string(rows * 3) +
                                   " values, more than a file of " + std::to_string(fs::file_size(file)) +
                                   " bytes can hold; expected a dataset that fits the file and at most 268435456 values";
      EXPECT_EQ(std::string(e.what()), expected);
    }
  }
  // A raw HDF5 log with such a dataset: the file is damaged, an error naming the dataset.
  const fs::path log = declaring_file(dir / "log.h5", "sensors", {hsize_t{1} << 31});
  try {
    read_raw_log(log);
    ADD_FAILURE() << "accepted the log";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("log.h5:/sensors: declares 2147483648 values"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

/// "episode,t,c0,c1,...": a header of `width` columns, and one row of zeros.
fs::path wide_csv(const fs::path& file, int width) {
  std::string header = "episode,t", row = "0,0";
  for (int c = 0; c < width - 2; ++c) {
    header += ",c" + std::to_string(c);
    row += ",0";
  }
  std::ofstream(file) << header << '\n' << row << '\n';
  return file;
}

TEST(CsvHeader, A200000ColumnHeaderGivesAShortMessage) {
  const fs::path dir = test::temporary_dir("hostile");
  const fs::path file = wide_csv(dir / "wide.csv", 200'000);
  try {
    read_measurements(file, test::cartpole_signature());
    ADD_FAILURE() << "accepted";
  } catch (const DataError& e) {
    const std::string message = e.what();
    EXPECT_LT(message.size(), 2000u) << message.substr(0, 2000);
    EXPECT_EQ(message.rfind(file.string() + ":line 1: the header columns do not match system 'cartpole':", 0), 0u)
        << message.substr(0, 2000);
    for (const char* part : {"missing 'x', 'x_dot', 'theta', 'theta_dot', 'force';",
                             "unknown 'c0', 'c1', 'c2', 'c3', 'c4', 'c5', 'c6', 'c7', 'c8', 'c9', ... and 199988 more;",
                             "found 200000 columns: episode,t,c0,c1,c2,c3,c4,c5,c6,c7,... and 199990 more;",
                             "expected the columns episode,t,x,x_dot,theta,theta_dot,force"})
      EXPECT_NE(message.find(part), std::string::npos) << part << "\n" << message;
  }
  // Long names are cut, repeated ones listed once.
  const std::string long_name(100'000, 'y');
  std::ofstream(dir / "long.csv") << "episode,t,x,x," << long_name << ",theta_dot,force\n0,0,0,0,0,0,0\n";
  try {
    read_measurements(dir / "long.csv", test::cartpole_signature());
    ADD_FAILURE() << "accepted";
  } catch (const DataError& e) {
    const std::string message = e.what();
    EXPECT_LT(message.size(), 1000u);
    EXPECT_NE(message.find("unknown '" + std::string(40, 'y') + "...'; repeated 'x';"), std::string::npos) << message;
  }
  fs::remove_all(dir);
}

TEST(CsvHeader, ARawLogOf200000ColumnsGivesShortMessages) {
  const fs::path dir = test::temporary_dir("hostile");
  const fs::path file = wide_csv(dir / "wide.csv", 200'000);
  const RawLog log = read_raw_log(file);
  EXPECT_EQ(log.columns.size(), 200'000u);
  EXPECT_LT(log.column_names().size(), 300u);
  EXPECT_NE(log.column_names().find("'c7', ... and 199990 more"), std::string::npos) << log.column_names();
  const std::string long_name(100'000, 'z');
  std::ofstream(dir / "twice.csv") << long_name << ",t," << long_name << "\n0,0,0\n";
  try {
    read_raw_log(dir / "twice.csv");
    ADD_FAILURE() << "accepted";
  } catch (const DataError& e) {
    EXPECT_LT(std::string(e.what()).size(), 300u);
    EXPECT_NE(std::string(e.what()).find("column '" + std::string(40, 'z') + "...' appears twice"), std::string::npos);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg
