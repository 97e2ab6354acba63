// The pieces of `gpilqg data import` with exact answers: the unit table, resampling (held controls
// and linearly interpolated states exact), splitting at gaps, the CSV / MAT / HDF5 log readers, and
// import_log's counts and errors on small logs.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/log_import.hpp"
#include "gpilqg/core/resampling.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/core/units.hpp"
#include "mat_file.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

TEST(UnitTable, FactorsToSi) {
  EXPECT_DOUBLE_EQ(find_unit("deg")->factor, std::numbers::pi / 180.0);
  EXPECT_DOUBLE_EQ(find_unit("deg/s")->factor, std::numbers::pi / 180.0);
  EXPECT_DOUBLE_EQ(find_unit("mm")->factor, 1e-3);
  EXPECT_DOUBLE_EQ(find_unit("ms")->factor, 1e-3);
  EXPECT_DOUBLE_EQ(find_unit("us")->factor, 1e-6);
  EXPECT_DOUBLE_EQ(find_unit("mm/s")->factor, 1e-3);
  EXPECT_DOUBLE_EQ(find_unit("N")->factor, 1.0);
  EXPECT_EQ(find_unit("ms")->dimension, "time");
  EXPECT_EQ(find_unit("deg/s")->si_unit, "rad/s");
  EXPECT_FALSE(find_unit("degree"));
  EXPECT_FALSE(find_unit("MM"));  // case matters: mm and Mm are different units
  EXPECT_NE(unit_names().find("deg/s"), std::string::npos);
  for (const UnitScale& u : unit_table()) EXPECT_TRUE(find_unit(u.name)) << u.name;
}

/// Times 0, 0.1, ... with +-5% jitter (deterministic).
Vector jittered_times(int count, double dt) {
  Vector t(count);
  for (int i = 0; i < count; ++i) t(i) = i * dt + 0.05 * dt * std::sin(1.7 * i + 0.3);
  return t;
}

TEST(Resampling, LinearStatesAreExactForLinearSignals) {
  const Vector t = jittered_times(50, 0.1);
  Matrix y(50, 2);
  for (int i = 0; i < 50; ++i) y.row(i) << 2.0 - 3.0 * t(i), 0.5 * t(i);
  const Vector tau = uniform_grid(t, 0.1);
  EXPECT_NEAR(tau(0), t(0), 0.0);
  EXPECT_LE(tau(tau.size() - 1), t(49));
  const Matrix z = interpolate_linear(t, y, tau);
  for (int k = 0; k < tau.size(); ++k) {
    EXPECT_NEAR(z(k, 0), 2.0 - 3.0 * tau(k), 1e-12);
    EXPECT_NEAR(z(k, 1), 0.5 * tau(k), 1e-12);
  }
}

TEST(Resampling, HeldControlsAreTheLastSampleAtOrBefore) {
  const Vector t = (Vector(5) << 0.0, 0.11, 0.19, 0.305, 0.4).finished();
  const Matrix u = (Matrix(5, 1) << 1, 2, 3, 4, 5).finished();
  const Vector tau = uniform_grid(t, 0.1);  // 0, 0.1, 0.2, 0.3, 0.4
  ASSERT_EQ(tau.size(), 5);
  const Matrix held = hold_zero_order(t, u, tau);
  // At 0.1 the control of t = 0 is still in force; at 0.2 that of 0.19; at 0.3 that of 0.19; at 0.4 the last.
  EXPECT_EQ(held(0, 0), 1);
  EXPECT_EQ(held(1, 0), 1);
  EXPECT_EQ(held(2, 0), 3);
  EXPECT_EQ(held(3, 0), 3);
  EXPECT_EQ(held(4, 0), 5);
  // A sample exactly on the grid is in force from that instant.
  EXPECT_EQ(hold_zero_order(t, u, Vector::Constant(1, 0.11))(0, 0), 2);
}

// A log whose times start far from 0 (a benchmark's 66.600960 s + k 1.6384 ms): the median step and
// the grid carry the times' rounding, which must neither move a held control to the previous sample
// nor drop the last one.
TEST(Resampling, RoundingOfLoggedTimesNeitherDelaysControlsNorDropsSamples) {
  const long n = 20000;
  Vector t(n), u(n);
  for (long i = 0; i < n; ++i) {
    t(i) = 66.600960 + static_cast<double>(i) * 0.0016384;
    u(i) = static_cast<double>(i % 7);
  }
  for (const double dt : {0.0016383999999902699, 0.0016384, 0.0016384000000097})
  {
    const Vector tau = uniform_grid(t, dt);
    ASSERT_EQ(tau.size(), n) << dt;
    const Matrix held = hold_zero_order(t, u, tau);
    for (long i = 0; i < n; ++i) ASSERT_EQ(held(i, 0), u(i)) << "sample " << i << ", dt " << dt;
  }
}

TEST(Resampling, AveragedControlsHaveTheImpulseOfTheHeldSignal) {
  const Vector t = (Vector(5) << 0.0, 0.11, 0.19, 0.305, 0.4).finished();
  const Matrix u = (Matrix(5, 1) << 1, 2, 3, 4, 5).finished();
  const Vector tau = uniform_grid(t, 0.1);
  const Matrix avg = average_held(t, u, tau, 0.1);
  // [0, 0.1): 1 throughout; [0.1, 0.2): 1 for 0.01, 2 for 0.08, 3 for 0.01; [0.3, 0.4): 3 for 0.005, 4 for 0.095.
  EXPECT_NEAR(avg(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(avg(1, 0), (0.01 * 1 + 0.08 * 2 + 0.01 * 3) / 0.1, 1e-12);
  EXPECT_NEAR(avg(2, 0), (0.09 * 3 + 0.01 * 3) / 0.1, 1e-12);
  EXPECT_NEAR(avg(3, 0), (0.005 * 3 + 0.095 * 4) / 0.1, 1e-12);
  EXPECT_NEAR(avg(4, 0), 5.0, 1e-12);  // past the last sample its value is held
  // With every switch on the grid the average is the hold.
  const Vector regular = (Vector(4) << 0.0, 0.1, 0.2, 0.3).finished();
  const Matrix v = (Matrix(4, 1) << 1, -2, 3, 7).finished();
  EXPECT_MATRIX_NEAR(average_held(regular, v, uniform_grid(regular, 0.1), 0.1), v, 1e-12);
}

TEST(Resampling, SplitsAtGapsLongerThanTheLimit) {
  const Vector t = (Vector(8) << 0.0, 0.1, 0.2, 0.5, 0.6, 0.7, 0.8, 1.2).finished();
  const auto ranges = split_at_gaps(t, 0.25);
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(ranges[0].begin, 0);
  EXPECT_EQ(ranges[0].end, 3);
  EXPECT_EQ(ranges[1].begin, 3);
  EXPECT_EQ(ranges[1].end, 7);
  EXPECT_EQ(ranges[2].size(), 1);
  EXPECT_EQ(split_at_gaps(t, 0.4).size(), 1u);  // a gap equal to the limit does not split
  EXPECT_NEAR(median_step(t, ranges), 0.1, 1e-12);
  EXPECT_THROW(split_at_gaps((Vector(2) << 1.0, 1.0).finished(), 1.0), std::invalid_argument);
}

TEST(RawLog, CsvTrimsFieldsAndKeepsTextColumnsAsUnusable) {
  const fs::path dir = test::temporary_dir("raw_csv");
  std::ofstream(dir / "log.csv") << "\xEF\xBB\xBFtime, pos ,mode\r\n0.0, 1.5, auto\r\n0.1, 1.25 ,manual\r\n\r\n";
  const RawLog log = read_raw_log(dir / "log.csv");
  ASSERT_EQ(log.columns.size(), 3u);
  EXPECT_EQ(log.columns[1].name, "pos");
  EXPECT_EQ(log.columns[1].values, (std::vector<double>{1.5, 1.25}));
  EXPECT_TRUE(log.columns[1].unusable.empty());
  EXPECT_NE(log.columns[2].unusable.find("line 2: 'auto' is not a finite number"), std::string::npos) << log.columns[2].unusable;
  EXPECT_EQ(log.location("pos", 1), "line 3, column 'pos'");

  std::ofstream(dir / "short.csv") << "a,b\n1,2\n3\n";
  try {
    read_raw_log(dir / "short.csv");
    FAIL() << "a short row must be rejected";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:line 3: 1 fields; expected 2 fields"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "twice.csv") << "a,a\n1,2\n";
  EXPECT_THROW(read_raw_log(dir / "twice.csv"), DataError);
  std::ofstream(dir / "log.txt") << "a\n1\n";
  EXPECT_THROW(read_raw_log(dir / "log.txt"), DataError);
  EXPECT_THROW(read_raw_log(dir / "none.csv"), DataError);
}

TEST(RawLog, MatVectorsAndStructFieldsAreColumns) {
  const fs::path dir = test::temporary_dir("raw_mat");
  const fs::path file = dir / "log.mat";
  test::write_mat_file(file, {{"time", {0.0, 0.1, 0.2}}, {"force", {1.0, -2.0, 3.5}}}, "sensors",
                       {{"cart", {0.01, 0.02, 0.03}}, {"angle", {10.0, 20.0, 30.0}}});
  const RawLog log = read_raw_log(file);
  EXPECT_EQ(log.format, LogFormat::Mat);
  ASSERT_NE(log.find("time"), nullptr);
  EXPECT_EQ(log.find("force")->values, (std::vector<double>{1.0, -2.0, 3.5}));
  ASSERT_NE(log.find("sensors.angle"), nullptr) << log.column_names();
  EXPECT_EQ(log.find("sensors.angle")->values, (std::vector<double>{10.0, 20.0, 30.0}));
  EXPECT_EQ(log.find("sensors.cart")->values, (std::vector<double>{0.01, 0.02, 0.03}));
  EXPECT_EQ(log.location("force", 2), "variable 'force', element 2");

  // A matrix variable is kept by name but cannot be used.
  mat_t* mat = Mat_CreateVer((dir / "matrix.mat").string().c_str(), nullptr, MAT_FT_MAT5);
  std::size_t dims[2] = {2, 3};
  double values[6] = {1, 2, 3, 4, 5, 6};
  matvar_t* var = Mat_VarCreate("image", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, values, 0);
  Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
  Mat_VarFree(var);
  matvar_t* t = test::mat_column("t", {0.0, 1.0});
  Mat_VarWrite(mat, t, MAT_COMPRESSION_NONE);
  Mat_VarFree(t);
  Mat_Close(mat);
  const RawLog with_matrix = read_raw_log(dir / "matrix.mat");
  ASSERT_NE(with_matrix.find("image"), nullptr);
  EXPECT_EQ(with_matrix.find("image")->unusable, "a 2 x 3 array, not a vector");

  std::ofstream(dir / "not.mat") << "not a mat file";
  EXPECT_THROW(read_raw_log(dir / "not.mat"), DataError);
}

TEST(RawLog, Hdf5VectorsAreColumnsNamedByPath) {
  const fs::path dir = test::temporary_dir("raw_hdf5");
  {
    Hdf5Writer h5(dir / "log.h5");
    h5.write_vector("/time", std::vector<double>{0.0, 0.1, 0.2});
    h5.write_vector("/sensors/cart", std::vector<double>{1.0, 2.0, 3.0});
    h5.write_matrix("/sensors/column", Matrix::Constant(3, 1, 7.0));
    h5.write_matrix("/image", Matrix::Zero(3, 4));
  }
  const RawLog log = read_raw_log(dir / "log.h5");
  ASSERT_NE(log.find("sensors/cart"), nullptr) << log.column_names();
  EXPECT_EQ(log.find("/sensors/cart"), log.find("sensors/cart"));  // the leading '/' is optional
  EXPECT_EQ(log.find("sensors/cart")->values, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(log.find("sensors/column")->values, (std::vector<double>{7.0, 7.0, 7.0}));
  EXPECT_EQ(log.find("image")->unusable, "a 3 x 4 array, not a vector");
  EXPECT_EQ(log.location("time", 1), "dataset '/time', element 1");
}

/// A cart-pole log of T rows at dt with every state, time in ms, theta in degrees.
RawLog cartpole_log(int rows, double dt) {
  RawLog log;
  log.file = "memory.csv";
  LogColumn t{"ms", {}, ""}, x{"x", {}, ""}, xd{"xd", {}, ""}, th{"th_deg", {}, ""}, thd{"thd", {}, ""}, f{"f", {}, ""},
      extra{"battery", {}, ""};
  for (int i = 0; i < rows; ++i) {
    const double time = i * dt;
    t.values.push_back(1000.0 * time);
    x.values.push_back(0.5 * time * time);
    xd.values.push_back(time);
    th.values.push_back(90.0 * time);
    thd.values.push_back(0.5 * std::numbers::pi);
    f.values.push_back(i % 3);
    extra.values.push_back(12.0);
  }
  log.columns = {t, x, xd, th, thd, f, extra};
  return log;
}

LogMap cartpole_map(bool with_velocities) {
  LogMap map;
  map.file = "map.toml";
  map.time = {"time", "ms", "ms", 1e-3, {"map.toml", 2, "time.column"}, ""};
  map.states = {{"x", "x", "", 1.0, {"map.toml", 5, "states.x.column"}, ""},
                {"theta", "th_deg", "deg", std::numbers::pi / 180.0, {"map.toml", 6, "states.theta.column"}, ""}};
  if (with_velocities) {
    map.states.push_back({"x_dot", "xd", "", 1.0, {"map.toml", 7, "states.x_dot.column"}, ""});
    map.states.push_back({"theta_dot", "thd", "", 1.0, {"map.toml", 8, "states.theta_dot.column"}, ""});
  } else {
    map.velocities = VelocityEstimator{5, 2, {"map.toml", 11, "velocities"}};
  }
  map.controls = {{"force", "f", "", 1.0, {"map.toml", 10, "controls.force.column"}, ""}};
  map.states_section = {"map.toml", 4, "states"};
  map.controls_section = {"map.toml", 9, "controls"};
  return map;
}

TEST(ImportLog, ScalesMapsAndReportsIgnoredColumns) {
  const ImportResult r = import_log(cartpole_log(30, 0.02), cartpole_map(true), system_signature("cartpole"));
  ASSERT_EQ(r.set.episodes.size(), 1u);
  const Episode& e = r.set.episodes[0];
  EXPECT_EQ(e.length(), 30);
  EXPECT_NEAR(e.dt(), 0.02, 1e-12);
  EXPECT_NEAR(e.x(10, 2), 0.5 * std::numbers::pi * 0.2, 1e-12);  // 90 deg/s * 0.2 s in rad
  EXPECT_NEAR(e.x(10, 0), 0.5 * 0.2 * 0.2, 1e-12);
  EXPECT_EQ(r.report.rows_read, 30);
  EXPECT_EQ(r.report.rows_used, 30);
  EXPECT_EQ(r.report.samples_written, 30);
  EXPECT_EQ(r.report.ignored_columns, std::vector<std::string>{"battery"});
  EXPECT_FALSE(r.report.dt_from_map);
}

TEST(ImportLog, EstimatesMissingVelocitiesExactlyForQuadratics) {
  const ImportResult r = import_log(cartpole_log(30, 0.02), cartpole_map(false), system_signature("cartpole"));
  const Episode& e = r.set.episodes[0];
  for (int k = 0; k < e.length(); ++k) {
    EXPECT_NEAR(e.x(k, 1), e.t(k), 1e-9);                          // d/dt of t^2 / 2
    EXPECT_NEAR(e.x(k, 3), 0.5 * std::numbers::pi, 1e-9);         // d/dt of 90 deg/s * t
  }
  ASSERT_EQ(r.report.estimated.size(), 2u);
  EXPECT_EQ(r.report.estimated[0], (std::pair<std::string, std::string>{"x_dot", "x"}));
  EXPECT_NEAR(r.report.estimator_noise_gain, std::sqrt(0.1) / 0.02, 1e-9);  // window 5: c = (-2..2) / 10
  EXPECT_EQ(r.report.estimator_lag, 0.0);
}

TEST(ImportLog, GapsSplitEpisodesAndShortPiecesAreDroppedAndCounted) {
  RawLog log = cartpole_log(40, 0.02);
  // Remove rows 10..24 (a 0.3 s hole) and rows 27..37, leaving 10, 2 (too short) and 2 rows.
  for (LogColumn& c : log.columns) {
    std::vector<double> kept;
    for (int i = 0; i < 40; ++i)
      if (!(i >= 10 && i < 25) && !(i >= 27 && i < 38)) kept.push_back(c.values[static_cast<std::size_t>(i)]);
    c.values = kept;
  }
  LogMap map = cartpole_map(true);
  map.max_gap = 0.1;
  const ImportResult r = import_log(log, map, system_signature("cartpole"));
  EXPECT_EQ(r.report.gaps, 2);
  EXPECT_EQ(r.set.episodes.size(), 3u);
  EXPECT_EQ(r.report.rows_read, 14);
  EXPECT_EQ(r.report.rows_used + r.report.rows_dropped, 14);
  EXPECT_TRUE(r.report.dropped.empty());
  // Each gap from the last sample before it to the first after: rows 9 -> 25 and 26 -> 38.
  ASSERT_EQ(r.report.gap_list.size(), 2u);
  EXPECT_NEAR(r.report.gap_list[0].t_start, 9 * 0.02, 1e-12);
  EXPECT_NEAR(r.report.gap_list[0].length(), 16 * 0.02, 1e-12);
  EXPECT_NEAR(r.report.gap_list[1].t_start, 26 * 0.02, 1e-12);
  EXPECT_NEAR(r.report.gap_list[1].length(), 12 * 0.02, 1e-12);
  ASSERT_EQ(r.report.records.size(), 1u);  // no episode column: the log is one record, cut in 3
  EXPECT_EQ(r.report.records[0].rows, 14);
  EXPECT_EQ(r.report.records[0].pieces, 3);
  EXPECT_EQ(r.report.records[0].episodes, 3);
  // With the velocity estimator (window 5), the 2-row pieces are too short and are dropped.
  LogMap estimating = cartpole_map(false);
  estimating.max_gap = 0.1;
  const ImportResult d = import_log(log, estimating, system_signature("cartpole"));
  EXPECT_EQ(d.set.episodes.size(), 1u);
  EXPECT_EQ(d.report.rows_dropped, 4);
  ASSERT_EQ(d.report.dropped.size(), 2u);
  EXPECT_NE(d.report.dropped[0].reason.find("expected at least 5"), std::string::npos) << d.report.dropped[0].reason;
  EXPECT_EQ(d.report.records[0].pieces, 3);
  EXPECT_EQ(d.report.records[0].episodes, 1);
}

std::string import_error(const RawLog& log, const LogMap& map) {
  try {
    import_log(log, map, system_signature("cartpole"));
  } catch (const DataError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ImportLog, ErrorsNameTheMapLineOrTheLogRow) {
  LogMap unknown = cartpole_map(true);
  unknown.states[1].column = "angle";
  const std::string e1 = import_error(cartpole_log(10, 0.02), unknown);
  EXPECT_NE(e1.find("map.toml:line 6: field 'states.theta.column': column 'angle' is not in memory.csv"), std::string::npos) << e1;
  EXPECT_NE(e1.find("'th_deg'"), std::string::npos) << e1;

  RawLog backwards = cartpole_log(10, 0.02);
  backwards.columns[0].values[6] = 90.0;
  const std::string e2 = import_error(backwards, cartpole_map(true));
  EXPECT_NE(e2.find("memory.csv:line 8, column 'ms': time 0.09 s is before the previous sample's 0.1 s"), std::string::npos) << e2;

  const std::string e3 = import_error(cartpole_log(1, 0.02), cartpole_map(true));
  EXPECT_NE(e3.find("memory.csv:column 'ms': 1 sample; expected at least 2 samples"), std::string::npos) << e3;

  LogMap missing = cartpole_map(true);
  missing.states.pop_back();  // theta_dot, and no estimator
  const std::string e4 = import_error(cartpole_log(10, 0.02), missing);
  EXPECT_NE(e4.find("map.toml:line 4: field 'states': state 'theta_dot' has no column and no estimator"), std::string::npos) << e4;

  LogMap twice = cartpole_map(true);
  twice.controls.push_back({"force", "x", "", 1.0, {"map.toml", 12, "controls.force.column"}, ""});
  EXPECT_NE(import_error(cartpole_log(10, 0.02), twice).find("map.toml:line 12"), std::string::npos);

  LogMap foreign = cartpole_map(true);
  foreign.controls[0].target = "u1";
  const std::string e5 = import_error(cartpole_log(10, 0.02), foreign);
  EXPECT_NE(e5.find("'u1' is not a control of cartpole; expected one of its controls: force"), std::string::npos) << e5;

  RawLog text = cartpole_log(10, 0.02);
  text.columns[1].unusable = "line 4: 'n/a' is not a finite number";
  const std::string e6 = import_error(text, cartpole_map(true));
  EXPECT_NE(e6.find("memory.csv:column 'x'"), std::string::npos) << e6;
  EXPECT_NE(e6.find("'n/a'"), std::string::npos) << e6;
}

/// A resampling step that turns a short log into more samples than the sample limit is refused,
/// naming the field and the count, before the grid is allocated.
TEST(ImportLog, ResamplingBeyondTheSampleLimitIsRefusedBeforeAllocation) {
  LogMap map = cartpole_map(true);
  map.resample_section = {"map.toml", 12, "resample"};
  map.dt = 1e-7;
  map.max_gap = 1.0;
  const std::string e = import_error(cartpole_log(240, 0.01), map);
  EXPECT_NE(e.find("map.toml:line 12: field 'resample.dt': 1e-07 s resamples the log's 240 rows to 23900001 samples; "
                   "expected at most 10000000 samples"),
            std::string::npos)
      << e;
  map.dt = 1e-5;  // 239,001 samples: within the limit
  EXPECT_EQ(import_log(cartpole_log(240, 0.01), map, system_signature("cartpole")).report.samples_written, 239001);
}

}  // namespace
}  // namespace gpilqg
