/// Measurement data I/O (docs/formats.md#measurement-data-csv-and-hdf5): every class of bad CSV and
/// HDF5 input is rejected with an error naming the file and the line or dataset; valid files round-trip
/// bit for bit; summarize() matches numbers computed by hand.

#include "gpilqg/core/measurements.hpp"

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <vector>

#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

/// The what() of the DataError thrown by `read`, or a note that none (or another type) was thrown.
std::string data_error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const DataError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("<not a DataError: ") + e.what() + ">";
  }
  return "<no error>";
}

const std::string kHeader = "episode,t,x,x_dot,theta,theta_dot,force\n";

// ------------------------------------------------------------------------------------------------
// Valid CSV

TEST(MeasurementsCsv, ReadsEpisodesInFileOrder) {
  const auto dir = test::temporary_dir("measurements");
  const auto file = test::write_text(dir / "ok.csv", kHeader +
                                                   "3,0,0.01,0.09,-0.18,-0.59,-11.2\n"
                                                   "3,0.05,0.02,0.1,-0.2,-0.6,-11\n"
                                                   "3,0.1,0.03,0.11,-0.22,-0.61,-10.5\n"
                                                   "1,1.5,1,2,3,4,5\n"
                                                   "1,1.6,1.1,2.1,3.1,4.1,5.1\n");
  const MeasurementSet set = read_measurements(file, test::cartpole_signature());
  EXPECT_EQ(set.system.name, "cartpole");
  ASSERT_EQ(set.episodes.size(), 2u);
  EXPECT_EQ(set.sample_count(), 5);
  const Episode& first = set.episodes[0];
  EXPECT_EQ(first.id, 3);
  EXPECT_EQ(first.length(), 3);
  EXPECT_DOUBLE_EQ(first.dt(), 0.05);
  ASSERT_EQ(first.x.rows(), 3);
  ASSERT_EQ(first.x.cols(), 4);
  ASSERT_EQ(first.u.cols(), 1);
  EXPECT_EQ(first.x(0, 0), 0.01);
  EXPECT_EQ(first.x(2, 3), -0.61);
  EXPECT_EQ(first.u(1, 0), -11.0);
  EXPECT_EQ(set.episodes[1].id, 1);
  EXPECT_EQ(set.episodes[1].t(0), 1.5);
  EXPECT_NEAR(set.episodes[1].dt(), 0.1, 1e-12);
}

TEST(MeasurementsCsv, AcceptsCrlfByteOrderMarkMissingFinalNewlineAndTrailingBlankLines) {
  const auto dir = test::temporary_dir("measurements");
  const std::string rows = "0,0,1,2,3,4,5\r\n0,0.5,1,2,3,4,5\r\n0,1,1,2,3,4,5";
  const std::string header = "episode,t,x,x_dot,theta,theta_dot,force\r\n";
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"crlf.csv", header + rows + "\r\n"},
           {"bom.csv", "\xEF\xBB\xBF" + header + rows + "\r\n"},
           {"no_final_newline.csv", header + rows},
           {"trailing_blank_lines.csv", header + rows + "\r\n\r\n  \n\n"}}) {
    SCOPED_TRACE(name);
    const MeasurementSet set = read_measurements_csv(test::write_text(dir / name, text), test::cartpole_signature());
    ASSERT_EQ(set.episodes.size(), 1u);
    EXPECT_EQ(set.episodes[0].length(), 3);
    EXPECT_EQ(set.episodes[0].u(2, 0), 5.0);
  }
}

// A continuous record needs no column of zeros: without `episode` the rows are one episode, id 0,
// and a short row names the columns of that header.
TEST(MeasurementsCsv, HeaderWithoutEpisodeColumnIsOneEpisode) {
  const auto dir = test::temporary_dir("measurements");
  const MeasurementSet set = read_measurements(
      test::write_text(dir / "record.csv", "t,x,x_dot,theta,theta_dot,force\n0,1,2,3,4,5\n0.5,1.5,2,3,4,6\n1,2,2,3,4,7\n"),
      test::cartpole_signature());
  ASSERT_EQ(set.episodes.size(), 1u);
  EXPECT_EQ(set.episodes[0].id, 0);
  EXPECT_EQ(set.episodes[0].length(), 3);
  EXPECT_DOUBLE_EQ(set.episodes[0].dt(), 0.5);
  EXPECT_EQ(set.episodes[0].x(1, 0), 1.5);
  EXPECT_EQ(set.episodes[0].u(2, 0), 7.0);
  try {
    read_measurements(test::write_text(dir / "short_row.csv", "t,x,x_dot,theta,theta_dot,force\n0,1,2,3,4,5\n0.5,1,2,3,4\n"),
                      test::cartpole_signature());
    FAIL() << "a short row was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3: the row has 5 fields; expected 6 fields (t,x,x_dot,theta,theta_dot,force)"),
              std::string::npos) << e.what();
  }
}

TEST(MeasurementsCsv, AcceptsDtWithinRelativeToleranceAndRejectsBeyond) {
  const auto dir = test::temporary_dir("measurements");
  // Times written with few digits: steps 0.0333 and 0.03330001 differ by 3e-7 relative (accepted);
  // 0.03331 differs by 3e-4 (rejected).
  const auto ok =
      test::write_text(dir / "ok.csv", kHeader + "0,0,0,0,0,0,0\n0,0.0333,0,0,0,0,0\n0,0.06660001,0,0,0,0,0\n");
  EXPECT_NO_THROW(read_measurements(ok, test::cartpole_signature()));
  const auto bad =
      test::write_text(dir / "bad.csv", kHeader + "0,0,0,0,0,0,0\n0,0.0333,0,0,0,0,0\n0,0.06661,0,0,0,0,0\n");
  const std::string error = data_error_of([&] { read_measurements(bad, test::cartpole_signature()); });
  EXPECT_NE(error.find("bad.csv:line 4: "), std::string::npos) << error;
}

// ------------------------------------------------------------------------------------------------
// Malformed CSV: one case per class of bad input, each with its own message.

struct BadCsvCase {
  std::string name;                   // also the file name: <name>.csv
  std::string text;                   // the whole file
  std::vector<std::string> expected;  // substrings of the error (besides "<name>.csv:")
};

std::ostream& operator<<(std::ostream& os, const BadCsvCase& c) { return os << c.name; }

const std::string kRow0a = "0,0,0.01,0.09,-0.18,-0.59,-11.2\n";
const std::string kRow0b = "0,0.05,0.02,0.1,-0.2,-0.6,-11\n";
const std::string kRow0c = "0,0.1,0.03,0.11,-0.22,-0.61,-10.5\n";
const std::string kRow1a = "1,0,1,2,3,4,5\n";
const std::string kRow1b = "1,0.05,1,2,3,4,5\n";

const std::vector<BadCsvCase> kBadCsvCases = {
    {"empty_file", "", {"line 1: the file is empty; expected a header line"}},
    {"only_blank_lines", "\n  \n\n", {"line 1: the file is empty"}},
    {"header_only", kHeader, {"line 2: no data rows after the header"}},
    {"blank_line_in_the_middle",
     kHeader + kRow0a + "\n" + kRow0b,
     {"line 3: blank line; expected a data row (blank lines are allowed only at the end of the file)"}},
    {"unknown_column",
     "episode,t,x,x_dot,theta,thetadot,force\n" + kRow0a + kRow0b,
     {"line 1: the header columns do not match system 'cartpole'", "missing 'theta_dot'", "unknown 'thetadot'",
      "found episode,t,x,x_dot,theta,thetadot,force",
      "expected the columns episode,t,x,x_dot,theta,theta_dot,force"}},
    {"missing_column",
     "episode,t,x,x_dot,theta,theta_dot\n0,0,1,2,3,4\n0,1,1,2,3,4\n",
     {"line 1:", "missing 'force';", "found episode,t,x,x_dot,theta,theta_dot;",
      "expected the columns episode,t,x,x_dot,theta,theta_dot,force"}},
    {"repeated_column",
     "episode,t,x,x,theta,theta_dot,force\n" + kRow0a + kRow0b,
     {"line 1:", "missing 'x_dot'", "repeated 'x'"}},
    {"columns_in_another_order",
     "episode,t,x_dot,x,theta,theta_dot,force\n" + kRow0a + kRow0b,
     {"line 1: the header has the right column names for system 'cartpole' but in a different order: found "
      "episode,t,x_dot,x,theta,theta_dot,force; expected the order episode,t,x,x_dot,theta,theta_dot,force"}},
    {"too_few_fields",
     kHeader + kRow0a + "0,0.05,0.02,0.1,-0.2,-0.6\n",
     {"line 3: the row has 6 fields; expected 7 fields (episode,t,x,x_dot,theta,theta_dot,force)"}},
    {"too_many_fields",
     kHeader + kRow0a + kRow0b + "0,0.1,0.03,0.11,-0.22,-0.61,-10.5,7\n",
     {"line 4: the row has 8 fields; expected 7 fields"}},
    {"trailing_garbage_in_number",
     kHeader + kRow0a + "0,0.05,0.02,0.1,-0.2abc,-0.6,-11\n",
     {"line 3: column 'theta': cannot read '-0.2abc' as a number; expected a plain decimal number"}},
    {"empty_field",
     kHeader + kRow0a + "0,0.05,,0.1,-0.2,-0.6,-11\n",
     {"line 3: column 'x': cannot read '' as a number"}},
    {"space_around_number",
     kHeader + kRow0a + "0,0.05,0.02, 0.1,-0.2,-0.6,-11\n",
     {"line 3: column 'x_dot': cannot read ' 0.1' as a number"}},
    {"nan_value",
     kHeader + kRow0a + "0,0.05,0.02,nan,-0.2,-0.6,-11\n",
     {"line 3: column 'x_dot': 'nan' is not a finite number; expected a finite number (no nan or inf)"}},
    {"infinite_value",
     kHeader + kRow0a + kRow0b + "0,0.1,0.03,0.11,-0.22,-0.61,-inf\n",
     {"line 4: column 'force': '-inf' is not a finite number"}},
    {"number_out_of_range",
     kHeader + kRow0a + "0,0.05,1e999,0.1,-0.2,-0.6,-11\n",
     {"line 3: column 'x': '1e999' is out of the range of a double"}},
    {"nan_time",
     kHeader + kRow0a + "0,nan,0.02,0.1,-0.2,-0.6,-11\n",
     {"line 3: column 't': 'nan' is not a finite number"}},
    {"fractional_episode",
     kHeader + kRow0a + "0.5,0.05,0.02,0.1,-0.2,-0.6,-11\n",
     {"line 3: column 'episode': '0.5' is not a non-negative integer; expected an episode number 0, 1, 2, "
      "..."}},
    {"negative_episode",
     kHeader + "-1,0,1,2,3,4,5\n-1,1,1,2,3,4,5\n",
     {"line 2: column 'episode': '-1' is not a non-negative integer"}},
    {"episode_not_contiguous",
     kHeader + kRow0a + kRow0b + kRow1a + kRow1b + kRow0c,
     {"line 6: episode 0 resumes after episode 1 started at line 4 (episode 0 began at line 2); expected all "
      "rows of an episode to be contiguous"}},
    {"repeated_time",
     kHeader + kRow0a + "0,0,0.02,0.1,-0.2,-0.6,-11\n",
     {"line 3: episode 0: t = 0 is not greater than the previous t = 0; expected t strictly increasing"}},
    {"decreasing_time",
     kHeader + kRow0a + kRow0b + "0,0.025,0.03,0.11,-0.22,-0.61,-10.5\n",
     {"line 4: episode 0: t = 0.025 is not greater than the previous t = 0.05"}},
    {"dt_not_constant",
     kHeader + kRow0a + kRow0b + kRow0c + "0,0.2,0,0,0,0,0\n",
     {"line 5: episode 0: dt = 0.1", "differs from the episode's first dt = 0.05",
      "expected dt = 0.05 (constant within an episode to relative tolerance 1e-06)"}},
    {"single_sample_episode",
     kHeader + kRow0a + kRow0b + kRow1a,
     {"line 4: episode 1 has 1 sample; need at least 2 to define dt; expected 2 or more samples"}},
};

class BadCsv : public ::testing::TestWithParam<BadCsvCase> {};

TEST_P(BadCsv, IsRejectedWithFileLineAndExpectation) {
  const BadCsvCase& c = GetParam();
  const auto file = test::write_text(test::temporary_dir("measurements") / (c.name + ".csv"), c.text);
  const std::string error = data_error_of([&] { read_measurements(file, test::cartpole_signature()); });
  EXPECT_EQ(error.rfind(file.string() + ":line ", 0), 0u)
      << "the error should start with the file and line: " << error;
  EXPECT_NE(error.find("; expected "), std::string::npos) << error;
  for (const std::string& part : c.expected)
    EXPECT_NE(error.find(part), std::string::npos) << "'" << part << "' not in: " << error;
}

INSTANTIATE_TEST_SUITE_P(Measurements, BadCsv, ::testing::ValuesIn(kBadCsvCases),
                         [](const ::testing::TestParamInfo<BadCsvCase>& info) { return info.param.name; });

TEST(MeasurementsCsv, ErrorCarriesFileAndLocation) {
  const auto file = test::write_text(test::temporary_dir("measurements") / "fields.csv", kHeader + kRow0a + "0,1\n");
  try {
    read_measurements_csv(file, test::cartpole_signature());
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.location(), "line 3");
    EXPECT_EQ(std::string(e.what()), file.string() +
                                         ":line 3: the row has 2 fields; expected 7 fields "
                                         "(episode,t,x,x_dot,theta,theta_dot,force)");
  }
}

TEST(Measurements, MissingFileAndUnknownExtensionAreDataErrors) {
  const auto dir = test::temporary_dir("measurements");
  EXPECT_EQ(data_error_of([&] { read_measurements(dir / "absent.csv", test::cartpole_signature()); }),
            (dir / "absent.csv").string() + ": no such file; expected a measurement file");
  EXPECT_EQ(data_error_of([&] { read_measurements(dir / "absent.h5", test::cartpole_signature()); }),
            (dir / "absent.h5").string() + ": no such file; expected a measurement file");
  const auto text = test::write_text(dir / "data.txt", kHeader + kRow0a + kRow0b);
  const std::string error = data_error_of([&] { read_measurements(text, test::cartpole_signature()); });
  EXPECT_NE(
      error.find("data.txt: unknown measurement file extension '.txt'; expected '.csv', '.h5' or '.hdf5'"),
      std::string::npos)
      << error;
  const auto not_hdf5 = test::write_text(dir / "data.h5", kHeader + kRow0a + kRow0b);
  EXPECT_NE(data_error_of([&] { read_measurements(not_hdf5, test::cartpole_signature()); }).find("data.h5: not an HDF5 file"),
            std::string::npos);
}

// ------------------------------------------------------------------------------------------------
// Round trip: CSV -> set -> HDF5 -> set -> CSV, bit for bit.

MeasurementSet awkward_set() {
  MeasurementSet set;
  set.system = test::cartpole_signature();
  const std::vector<double> specials = {0.1,
                                        1.0 / 3.0,
                                        -0.0,
                                        1e-300,
                                        5e-324,
                                        std::numeric_limits<double>::max(),
                                        -2.5e17,
                                        123456789.123456789,
                                        std::nextafter(1.0, 2.0)};
  const std::vector<std::pair<long, int>> shapes = {{0, 5}, {7, 2}, {12, 9}};
  std::size_t k = 0;
  for (const auto& [id, T] : shapes) {
    Episode e;
    e.id = id;
    e.t.resize(T);
    const double t0 = 0.1 * static_cast<double>(id), dt = 1.0 / 30.0;
    for (int i = 0; i < T; ++i) e.t(i) = t0 + dt * i;
    e.x = Matrix(T, 4);
    e.u = Matrix(T, 1);
    const Vector noise = test::random_vector(5 * T, -10.0, 10.0, static_cast<unsigned>(id + 1));
    for (int i = 0; i < T; ++i) {
      for (int j = 0; j < 4; ++j) e.x(i, j) = (k < specials.size()) ? specials[k++] : noise(5 * i + j);
      e.u(i, 0) = noise(5 * i + 4);
    }
    set.episodes.push_back(std::move(e));
  }
  return set;
}

::testing::AssertionResult bitwise_equal(const Matrix& a, const Matrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return ::testing::AssertionFailure() << "shapes differ";
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < a.cols(); ++j)
      if (std::bit_cast<std::uint64_t>(a(i, j)) != std::bit_cast<std::uint64_t>(b(i, j)))
        return ::testing::AssertionFailure() << "(" << i << ", " << j << "): " << a(i, j) << " vs " << b(i, j);
  return ::testing::AssertionSuccess();
}

void expect_same_set(const MeasurementSet& a, const MeasurementSet& b) {
  ASSERT_EQ(a.episodes.size(), b.episodes.size());
  for (std::size_t k = 0; k < a.episodes.size(); ++k) {
    SCOPED_TRACE("episode index " + std::to_string(k));
    EXPECT_EQ(a.episodes[k].id, b.episodes[k].id);
    EXPECT_TRUE(bitwise_equal(a.episodes[k].t, b.episodes[k].t));
    EXPECT_TRUE(bitwise_equal(a.episodes[k].x, b.episodes[k].x));
    EXPECT_TRUE(bitwise_equal(a.episodes[k].u, b.episodes[k].u));
  }
}

TEST(Measurements, RoundTripCsvHdf5CsvIsBitForBit) {
  const auto dir = test::temporary_dir("measurements");
  const MeasurementSet original = awkward_set();
  write_measurements(dir / "first.csv", original);
  const MeasurementSet from_csv = read_measurements(dir / "first.csv", test::cartpole_signature());
  expect_same_set(original, from_csv);
  write_measurements(dir / "copy.h5", from_csv);
  const MeasurementSet from_hdf5 = read_measurements(dir / "copy.h5", test::cartpole_signature());
  expect_same_set(original, from_hdf5);
  write_measurements(dir / "second.csv", from_hdf5);
  const std::string first = test::read_text(dir / "first.csv"), second = test::read_text(dir / "second.csv");
  EXPECT_FALSE(first.empty());
  EXPECT_EQ(first, second);
  EXPECT_EQ(first.substr(0, kHeader.size()), kHeader);
  // No temporary files left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 3);
}

TEST(Measurements, WritersRefuseSetsTheReadersWouldReject) {
  const auto dir = test::temporary_dir("measurements");
  MeasurementSet set = awkward_set();
  set.episodes[1].x(1, 2) = std::nan("");
  EXPECT_THROW(write_measurements(dir / "bad.csv", set), std::invalid_argument);
  EXPECT_THROW(write_measurements(dir / "bad.h5", set), std::invalid_argument);
  set = awkward_set();
  set.episodes[0].u = Matrix::Zero(5, 2);
  EXPECT_THROW(write_measurements(dir / "bad.csv", set), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "bad.csv"));
  EXPECT_FALSE(fs::exists(dir / "bad.h5"));
}

// ------------------------------------------------------------------------------------------------
// HDF5: valid variants and one case per class of bad input.

MeasurementSet small_set() {
  MeasurementSet set;
  set.system = test::cartpole_signature();
  for (long id : {10L, 2L}) {
    Episode e;
    e.id = id;
    e.t = Vector::LinSpaced(3, 0.0, 0.1);
    e.x = Matrix::Constant(3, 4, static_cast<double>(id));
    e.u = Matrix::Constant(3, 1, -1.0);
    set.episodes.push_back(std::move(e));
  }
  return set;
}

void write_fixed_strings(H5::Group& root, const std::string& name, const std::vector<std::string>& values,
                         H5T_str_t padding, bool scalar) {
  std::size_t size = 1;
  for (const auto& v : values) size = std::max(size, v.size() + 2);
  H5::StrType type(H5::PredType::C_S1, size);
  type.setStrpad(padding);
  std::string buffer;
  for (const auto& v : values)
    buffer += v + std::string(size - v.size(), padding == H5T_STR_SPACEPAD ? ' ' : '\0');
  root.removeAttr(name);
  const hsize_t dims[1] = {values.size()};
  const H5::DataSpace space = scalar ? H5::DataSpace(H5S_SCALAR) : H5::DataSpace(1, dims);
  root.createAttribute(name, type, space).write(type, buffer.data());
}

TEST(MeasurementsHdf5, OrdersEpisodesByNumberAndAcceptsFixedLengthStrings) {
  const auto file = test::temporary_dir("measurements") / "fixed.h5";
  write_measurements_hdf5(file, small_set());
  {
    H5::H5File h5(file.c_str(), H5F_ACC_RDWR);
    H5::Group root = h5.openGroup("/");
    write_fixed_strings(root, "system", {"cartpole"}, H5T_STR_NULLTERM, true);
    write_fixed_strings(root, "state_names", names_of(test::cartpole_signature().states), H5T_STR_NULLPAD, false);
    write_fixed_strings(root, "control_names", names_of(test::cartpole_signature().controls), H5T_STR_SPACEPAD, false);
  }
  const MeasurementSet set = read_measurements(file, test::cartpole_signature());
  ASSERT_EQ(set.episodes.size(), 2u);
  EXPECT_EQ(set.episodes[0].id, 2);  // "10" < "2" as names, but 2 < 10 as numbers
  EXPECT_EQ(set.episodes[1].id, 10);
  EXPECT_EQ(set.episodes[1].x(2, 3), 10.0);
}

using Mutation = std::function<void(H5::H5File&)>;

struct BadHdf5Case {
  std::string name;
  Mutation mutate;                    // applied to a valid file with episodes 2 and 10 (T = 3)
  std::vector<std::string> expected;  // substrings of the error (besides "<name>.h5:")
};

std::ostream& operator<<(std::ostream& os, const BadHdf5Case& c) { return os << c.name; }

void replace_dataset(H5::H5File& h5, const std::string& path, const std::vector<hsize_t>& dims,
                     const std::vector<double>& values) {
  h5.unlink(path);
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  h5.createDataSet(path, H5::PredType::IEEE_F64LE, space).write(values.data(), H5::PredType::NATIVE_DOUBLE);
}

void replace_string_attribute(H5::H5File& h5, const std::string& name, const std::vector<std::string>& values,
                              bool scalar) {
  H5::Group root = h5.openGroup("/");
  write_fixed_strings(root, name, values, H5T_STR_NULLTERM, scalar);
}

const std::vector<BadHdf5Case> kBadHdf5Cases = {
    {"missing_dataset",
     [](H5::H5File& h5) { h5.unlink("/episodes/10/u"); },
     {":/episodes/10/u: missing; expected shape (3 x 1)"}},
    {"wrong_shape",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/x", {3, 3}, std::vector<double>(9, 0.0));
     },
     {":/episodes/2/x: has shape (3 x 3); expected shape (3 x 4): T = 3 samples as in /episodes/2/t, n = 4 "
      "states "
      "['x', 'x_dot', 'theta', 'theta_dot']"}},
    {"u_one_dimensional",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/u", {3}, {1.0, 2.0, 3.0});
     },
     {":/episodes/2/u: has shape (3); expected shape (3 x 1)"}},
    {"t_two_dimensional",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/t", {3, 1}, {0.0, 0.05, 0.1});
     },
     {":/episodes/2/t: has shape (3 x 1); expected a 1-D float64 dataset"}},
    {"system_mismatch",
     [](H5::H5File& h5) { replace_string_attribute(h5, "system", {"quadrotor"}, true); },
     {":attribute 'system': the file holds data of system 'quadrotor'; expected 'cartpole'"}},
    {"state_names_mismatch",
     [](H5::H5File& h5) {
       replace_string_attribute(h5, "state_names", {"x", "v", "theta", "omega"}, false);
     },
     {":attribute 'state_names': is ['x', 'v', 'theta', 'omega']; expected the state names of system "
      "'cartpole' in "
      "order: ['x', 'x_dot', 'theta', 'theta_dot']"}},
    {"control_names_missing",
     [](H5::H5File& h5) { h5.openGroup("/").removeAttr("control_names"); },
     {":attribute 'control_names': missing; expected the control names"}},
    {"non_finite_state",
     [](H5::H5File& h5) {
       std::vector<double> x(12, 0.0);
       x[1 * 4 + 2] = std::numeric_limits<double>::quiet_NaN();
       replace_dataset(h5, "/episodes/10/x", {3, 4}, x);
     },
     {":/episodes/10/x: entry [1, 2] (sample 1, state 'theta') is nan; expected finite values only"}},
    {"non_finite_time",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/t", {3}, {0.0, std::numeric_limits<double>::infinity(), 0.1});
     },
     {":/episodes/2/t: entry [1] is inf"}},
    {"non_increasing_time",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/t", {3}, {0.0, 0.05, 0.05});
     },
     {":/episodes/2/t: at index 2: t = 0.05 is not greater than the previous t = 0.05"}},
    {"dt_not_constant",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/t", {3}, {0.0, 0.05, 0.2});
     },
     {":/episodes/2/t: at index 2: dt = 0.15", "expected dt = 0.05 (constant"}},
    {"single_sample",
     [](H5::H5File& h5) {
       replace_dataset(h5, "/episodes/2/t", {1}, {0.0});
       replace_dataset(h5, "/episodes/2/x", {1, 4}, {0.0, 0.0, 0.0, 0.0});
       replace_dataset(h5, "/episodes/2/u", {1, 1}, {0.0});
     },
     {":/episodes/2/t: the episode has 1 sample; need at least 2 to define dt"}},
    {"no_episodes",
     [](H5::H5File& h5) {
       h5.unlink("/episodes/2");
       h5.unlink("/episodes/10");
     },
     {":/episodes: holds no episodes; expected a group /episodes"}},
    {"episodes_group_missing", [](H5::H5File& h5) { h5.unlink("/episodes"); }, {":/episodes: missing"}},
    {"non_integer_episode_name",
     [](H5::H5File& h5) { h5.createGroup("/episodes/first"); },
     {":/episodes/first: the name is not a non-negative integer"}},
    {"integer_time_type",
     [](H5::H5File& h5) {
       h5.unlink("/episodes/2/t");
       const hsize_t dims[1] = {3};
       const int values[3] = {0, 1, 2};
       h5.createDataSet("/episodes/2/t", H5::PredType::STD_I32LE, H5::DataSpace(1, dims))
           .write(values, H5::PredType::NATIVE_INT);
     },
     {":/episodes/2/t: does not hold floating-point numbers"}},
    // A damaged or hostile file can declare any extent (chunked, nothing stored): refused before the
    // reader allocates 8e11 doubles.
    {"extent_beyond_the_file",
     [](H5::H5File& h5) {
       h5.unlink("/episodes/2/t");
       const hsize_t dims[1] = {800'000'000'000ull}, chunk[1] = {1024};
       H5::DSetCreatPropList properties;
       properties.setChunk(1, chunk);
       h5.createDataSet("/episodes/2/t", H5::PredType::IEEE_F64LE, H5::DataSpace(1, dims), properties);
     },
     {":/episodes/2/t: declares 800000000000 values, more than a file of "}},
    {"system_attribute_without_value",
     [](H5::H5File& h5) {
       H5::Group root = h5.openGroup("/");
       root.removeAttr("system");
       root.createAttribute("system", H5::StrType(H5::PredType::C_S1, H5T_VARIABLE), H5::DataSpace(H5S_NULL));
     },
     {":attribute 'system': "}},
};

class BadHdf5 : public ::testing::TestWithParam<BadHdf5Case> {};

TEST_P(BadHdf5, IsRejectedWithFileDatasetAndExpectation) {
  const BadHdf5Case& c = GetParam();
  const auto file = test::temporary_dir("measurements") / (c.name + ".h5");
  write_measurements_hdf5(file, small_set());
  {
    H5::H5File h5(file.c_str(), H5F_ACC_RDWR);
    c.mutate(h5);
  }
  const std::string error = data_error_of([&] { read_measurements(file, test::cartpole_signature()); });
  EXPECT_EQ(error.rfind(file.string() + ":", 0), 0u) << "the error should start with the file: " << error;
  EXPECT_NE(error.find("; expected "), std::string::npos) << error;
  for (const std::string& part : c.expected)
    EXPECT_NE(error.find(part), std::string::npos) << "'" << part << "' not in: " << error;
}

INSTANTIATE_TEST_SUITE_P(Measurements, BadHdf5, ::testing::ValuesIn(kBadHdf5Cases),
                         [](const ::testing::TestParamInfo<BadHdf5Case>& info) { return info.param.name; });

// ------------------------------------------------------------------------------------------------
// summarize(), against numbers computed by hand.

TEST(Measurements, SummarizeMatchesHandComputedStatistics) {
  MeasurementSet set;
  set.system = test::cartpole_signature();
  Episode a;  // dt 0.5, 3 samples
  a.id = 0;
  a.t = (Vector(3) << 0.0, 0.5, 1.0).finished();
  a.x = Matrix::Zero(3, 4);
  a.x.col(0) << 1.0, 2.0, 3.0;
  a.x.col(2) << -1.0, -1.0, -1.0;
  a.u = (Matrix(3, 1) << -1.0, 1.0, -1.0).finished();
  Episode b;  // dt 0.25, 2 samples
  b.id = 1;
  b.t = (Vector(2) << 2.0, 2.25).finished();
  b.x = Matrix::Zero(2, 4);
  b.x.col(0) << 4.0, 6.0;
  b.x.col(2) << -1.0, -1.0;
  b.u = (Matrix(2, 1) << 0.0, 0.0).finished();
  set.episodes = {a, b};

  const MeasurementSummary s = summarize(set);
  EXPECT_EQ(s.system, "cartpole");
  EXPECT_EQ(s.episodes, 2);
  EXPECT_EQ(s.samples, 5);
  EXPECT_DOUBLE_EQ(s.dt_min, 0.25);
  EXPECT_DOUBLE_EQ(s.dt_max, 0.5);
  EXPECT_DOUBLE_EQ(s.duration, 1.25);  // 1.0 + 0.25
  ASSERT_EQ(s.states.size(), 4u);
  ASSERT_EQ(s.controls.size(), 1u);

  // x: 1, 2, 3, 4, 6 -> mean 16/5 = 3.2; squared deviations 4.84 + 1.44 + 0.04 + 0.64 + 7.84 = 14.8;
  // population variance 14.8 / 5 = 2.96.
  EXPECT_EQ(s.states[0].name, "x");
  EXPECT_EQ(s.states[0].unit, "m");
  EXPECT_DOUBLE_EQ(s.states[0].min, 1.0);
  EXPECT_DOUBLE_EQ(s.states[0].max, 6.0);
  EXPECT_DOUBLE_EQ(s.states[0].mean, 3.2);
  EXPECT_DOUBLE_EQ(s.states[0].std, std::sqrt(2.96));
  // theta: constant -1 -> std exactly 0.
  EXPECT_EQ(s.states[2].name, "theta");
  EXPECT_EQ(s.states[2].unit, "rad");
  EXPECT_EQ(s.states[2].mean, -1.0);
  EXPECT_EQ(s.states[2].std, 0.0);
  // force: -1, 1, -1, 0, 0 -> mean -0.2; squared deviations 0.64 + 1.44 + 0.64 + 0.04 + 0.04 = 2.8;
  // population variance 0.56.
  EXPECT_EQ(s.controls[0].name, "force");
  EXPECT_EQ(s.controls[0].unit, "N");
  EXPECT_DOUBLE_EQ(s.controls[0].min, -1.0);
  EXPECT_DOUBLE_EQ(s.controls[0].max, 1.0);
  EXPECT_DOUBLE_EQ(s.controls[0].mean, -0.2);
  EXPECT_DOUBLE_EQ(s.controls[0].std, std::sqrt(0.56));
}

}  // namespace
}  // namespace gpilqg
