// `gpilqg data import` end to end: logs of one hidden-effect world written with real-world defects
// (timestamp jitter, a dropped block, extra columns, degrees and millimetres, positions only) as CSV,
// MAT and HDF5 import into files whose diagnosis names the same effect as the clean data, with the
// fitted parameter within 20%. And bad maps and logs: exit 2 naming the file, line and field or column.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "diagnosis_support.hpp"
#include "gpilqg/control/rollout.hpp"
#include "gpilqg/core/hdf5_writer.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/savitzky_golay.hpp"
#include "mat_file.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::quote;

constexpr int kEpisodes = 7;
constexpr int kSamples = 120;
constexpr double kLogDt = 0.02;
constexpr int kFine = 40;  ///< simulation steps per sample: 0.5 ms, so +-5% jitter is +-2 fine steps
constexpr double kMu = 1.2;

/// One episode as a logger records it: sample times (possibly jittered), the states at those times
/// (with observation noise) and the control the controller set at each sample.
struct LoggedEpisode {
  std::vector<double> t;
  Matrix x;  ///< samples x 4
  std::vector<double> u;
};

/// The cart-pole world with hidden Coulomb friction (mu = 1.2 N), integrated with RK4 at 0.5 ms.
/// The controller runs at the sample times and holds each random level (+-5 N) for 5 samples; with
/// `jitter` the sample times are k dt + j * 0.5 ms, j uniform in -2..2 (+-5% of dt), and the control
/// switches at those times, so the jittered log is as physical as the clean one. The same seed gives
/// the same initial states, controls and process noise with and without jitter.
std::vector<LoggedEpisode> simulate_logs(bool jitter, std::uint64_t seed) {
  ModelSpec spec;
  spec = spec.with(find_effect("cartpole", "cart_coulomb_friction"), Vector::Constant(1, kMu));
  const DynamicsPtr world = spec.build(test::actuator_noise(1, 0.02));
  const double fine = kLogDt / kFine;
  const auto model = make_step_model(world, Integrator::RK4, fine, 1);
  std::mt19937_64 rng(seed), jitter_rng(seed + 1000);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_int_distribution<int> offset(-2, 2);
  std::normal_distribution<double> normal(0.0, 1e-3);
  std::vector<LoggedEpisode> logs;
  for (int e = 0; e < kEpisodes; ++e) {
    Vector x0(4);
    for (int i = 0; i < 4; ++i) x0(i) = 0.1 * uniform(rng);
    std::vector<double> u(kSamples);
    for (int k = 0; k < kSamples; ++k) u[k] = k % 5 == 0 ? 5.0 * uniform(rng) : u[k - 1];
    std::vector<int> index(kSamples);
    for (int k = 0; k < kSamples; ++k) {
      const int j = offset(jitter_rng);
      index[k] = kFine * k + (jitter && k > 0 && k < kSamples - 1 ? j : 0);
    }
    const int steps = index.back();
    Matrix U(1, steps);
    for (int k = 0; k + 1 < kSamples; ++k)
      for (int i = index[k]; i < index[k + 1]; ++i) U(0, i) = u[k];
    const RolloutResult r = rollout(*model, x0, U, RolloutNoise::Process, &rng);
    EXPECT_TRUE(r.finite);
    LoggedEpisode log;
    log.x.resize(kSamples, 4);
    for (int k = 0; k < kSamples; ++k) {
      log.t.push_back(index[k] * fine);
      for (int i = 0; i < 4; ++i) log.x(k, i) = r.trajectory.x(i, index[k]) + normal(rng);
    }
    log.u = u;
    logs.push_back(std::move(log));
  }
  return logs;
}

MeasurementSet as_measurements(const std::vector<LoggedEpisode>& logs) {
  MeasurementSet set;
  set.system = system_signature("cartpole");
  for (std::size_t e = 0; e < logs.size(); ++e) {
    Episode episode;
    episode.id = static_cast<long>(e);
    episode.t.resize(kSamples);
    for (int k = 0; k < kSamples; ++k) episode.t(k) = k * kLogDt;
    episode.x = logs[e].x;
    episode.u = Eigen::Map<const Vector>(logs[e].u.data(), kSamples);
    set.episodes.push_back(std::move(episode));
  }
  return set;
}

/// A log as named columns, written as CSV, MAT or HDF5 by the tests.
struct LogTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  void add(const std::string& name, std::vector<double> values) {
    names.push_back(name);
    columns.push_back(std::move(values));
  }
};

/// The logs as columns; `keep(e, k)` selects rows; `x_scale`/`angle_scale` write in other units.
LogTable table_of(const std::vector<LoggedEpisode>& logs, double time_scale, double x_scale, double angle_scale,
                  bool velocities, const std::function<bool(int, int)>& keep) {
  std::vector<double> trial, t, x, xd, th, thd, force;
  for (std::size_t e = 0; e < logs.size(); ++e)
    for (int k = 0; k < kSamples; ++k) {
      if (!keep(static_cast<int>(e), k)) continue;
      trial.push_back(static_cast<double>(e));
      t.push_back(logs[e].t[k] * time_scale);
      x.push_back(logs[e].x(k, 0) * x_scale);
      xd.push_back(logs[e].x(k, 1) * x_scale);
      th.push_back(logs[e].x(k, 2) * angle_scale);
      thd.push_back(logs[e].x(k, 3) * angle_scale);
      force.push_back(logs[e].u[k]);
    }
  LogTable table;
  table.add("trial", trial);
  table.add("time", t);
  table.add("cart_pos", x);
  if (velocities) table.add("cart_vel", xd);
  table.add("pole_angle", th);
  if (velocities) table.add("pole_rate", thd);
  table.add("force", force);
  return table;
}

void write_csv(const fs::path& file, const LogTable& table, const std::vector<std::string>& text_column = {}) {
  std::ofstream out(file);
  for (std::size_t c = 0; c < table.names.size(); ++c) out << (c ? "," : "") << table.names[c];
  if (!text_column.empty()) out << ",mode";
  out << '\n';
  out.precision(17);
  for (std::size_t r = 0; r < table.columns[0].size(); ++r) {
    for (std::size_t c = 0; c < table.names.size(); ++c) out << (c ? "," : "") << table.columns[c][r];
    if (!text_column.empty()) out << "," << text_column[r % text_column.size()];
    out << '\n';
  }
}

const std::string kMapHead = "[time]\ncolumn = \"time\"\n\n[episode]\ncolumn = \"trial\"\n\n";
const std::string kControls = "[controls]\nforce = \"force\"\n";
const std::string kStatesSi =
    "[states]\nx = { column = \"cart_pos\" }\nx_dot = { column = \"cart_vel\" }\ntheta = { column = \"pole_angle\" }\n"
    "theta_dot = { column = \"pole_rate\" }\n\n";

fs::path write_map(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file;
}

struct Diagnosis {
  std::string effect;
  double value = 0.0;
};

Diagnosis diagnosis_of(const fs::path& data) {
  const auto result = test::run_cli("diagnose --system cartpole --data " + quote(data) + " --json --gp-points 100 --gp-restarts 0");
  EXPECT_EQ(result.status, 0) << result.err;
  if (result.status != 0) return {};
  const json j = json::parse(result.out);
  if (j["verdict"]["effect"].is_null()) return {"none", 0.0};
  const json& parameters = j["verdict"]["parameters"];  // {"mu": ...} for the Coulomb friction
  return {j["verdict"]["effect"].get<std::string>(), parameters.empty() ? 0.0 : parameters.begin()->get<double>()};
}

json import(const fs::path& log, const fs::path& map, const fs::path& out) {
  const auto result = test::run_cli("data import " + quote(log) + " --system cartpole --map " + quote(map) + " --out " +
                                    quote(out) + " --json");
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  return result.status == 0 ? json::parse(result.out) : json();
}

/// Each test makes the clean data and its diagnosis itself, in a folder of its own, so tests can run
/// in parallel processes (ctest -j).
class DataImportDefectsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::temporary_dir("data_import");
    clean_logs = simulate_logs(false, 5);
    write_measurements(dir / "clean.csv", as_measurements(clean_logs));
    clean = diagnosis_of(dir / "clean.csv");
  }
  /// The imported file's diagnosis names the clean data's effect, with mu within 20% of its value.
  void expect_same_diagnosis(const fs::path& imported, const std::string& defect) const {
    ASSERT_EQ(clean.effect, "cart_coulomb_friction") << "the clean data must show the hidden effect";
    const Diagnosis d = diagnosis_of(imported);
    std::cout << "[ diagnosis ] " << defect << ": " << d.effect << " mu = " << d.value << " (clean: " << clean.value << ")\n";
    EXPECT_EQ(d.effect, clean.effect) << defect;
    EXPECT_NEAR(d.value, clean.value, 0.2 * clean.value) << defect;
  }
  fs::path dir;
  std::vector<LoggedEpisode> clean_logs;
  Diagnosis clean;
};

const auto kAll = [](int, int) { return true; };

TEST_F(DataImportDefectsCli, CleanDataNamesTheHiddenEffect) {
  std::cout << "[ diagnosis ] clean: " << clean.effect << " mu = " << clean.value << '\n';
  EXPECT_EQ(clean.effect, "cart_coulomb_friction");
  EXPECT_NEAR(clean.value, kMu, 0.2 * kMu);
}

TEST_F(DataImportDefectsCli, TimestampJitterIsResampled) {
  const auto logs = simulate_logs(true, 5);
  const fs::path log = dir / "jitter.csv";
  write_csv(log, table_of(logs, 1.0, 1.0, 1.0, true, kAll));
  // A switch logged late would be held for the whole grid step with controls = "hold" (the control in
  // force at the grid time), which biases the fitted friction by ~15% and hides the effect on some
  // seeds; the step average gives each grid step the control's true impulse.
  const fs::path map = write_map(dir / "jitter.toml", kMapHead + "[resample]\ndt = 0.02\ncontrols = \"average\"\n\n" + kStatesSi + kControls);
  const json report = import(log, map, dir / "jitter.h5");
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["episodes"], kEpisodes);
  EXPECT_EQ(report["rows"]["read"], kEpisodes * kSamples);
  EXPECT_EQ(report["rows"]["dropped"], 0);
  EXPECT_EQ(report["dt_source"], "map");
  EXPECT_EQ(report["controls"], "average");
  EXPECT_GT(report["logged_step"]["max"].get<double>(), kLogDt);  // the jitter is there
  EXPECT_LT(report["logged_step"]["min"].get<double>(), kLogDt);
  expect_same_diagnosis(dir / "jitter.h5", "jitter");
}

TEST_F(DataImportDefectsCli, ADroppedBlockSplitsAnEpisode) {
  const fs::path log = dir / "dropped.h5";
  // 20 samples (0.4 s) of episode 3 lost; an HDF5 log of 1-D datasets under /log.
  const LogTable table = table_of(clean_logs, 1.0, 1.0, 1.0, true, [](int e, int k) { return !(e == 3 && k >= 50 && k < 70); });
  {
    Hdf5Writer h5(log);
    for (std::size_t c = 0; c < table.names.size(); ++c) h5.write_vector("/log/" + table.names[c], table.columns[c]);
  }
  std::string states = kStatesSi, head = kMapHead;
  for (const std::string name : {"cart_pos", "cart_vel", "pole_angle", "pole_rate"})
    states.replace(states.find("\"" + name + "\""), name.size() + 2, "\"log/" + name + "\"");
  head.replace(head.find("\"time\""), 6, "\"/log/time\"");
  head.replace(head.find("\"trial\""), 7, "\"log/trial\"");
  const fs::path map =
      write_map(dir / "dropped.toml", head + "[resample]\nmax_gap = 0.05\n\n" + states + "[controls]\nforce = \"log/force\"\n");
  const json report = import(log, map, dir / "dropped.h5.out.h5");
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["format"], "hdf5");
  EXPECT_EQ(report["episodes"], kEpisodes + 1);
  EXPECT_EQ(report["gaps_split"], 1);
  EXPECT_EQ(report["rows"]["read"], kEpisodes * kSamples - 20);
  EXPECT_EQ(report["samples_written"], kEpisodes * kSamples - 20);
  EXPECT_EQ(report["dt_source"], "median step");
  EXPECT_NEAR(report["dt"].get<double>(), kLogDt, 1e-12);
  expect_same_diagnosis(dir / "dropped.h5.out.h5", "dropped block");
}

TEST_F(DataImportDefectsCli, ExtraColumnsAreIgnoredAndListed) {
  LogTable table = table_of(clean_logs, 1000.0, 1.0, 1.0, true, kAll);  // time in ms
  std::vector<double> battery(table.columns[0].size()), temperature(table.columns[0].size());
  for (std::size_t r = 0; r < battery.size(); ++r) {
    battery[r] = 24.0 - 1e-3 * static_cast<double>(r);
    temperature[r] = 40.0 + std::sin(0.01 * static_cast<double>(r));
  }
  LogTable extra;  // battery_v after the time column, motor_temp last, then the text column "mode"
  for (std::size_t c = 0; c < table.names.size(); ++c) {
    extra.add(table.names[c], table.columns[c]);
    if (table.names[c] == "time") extra.add("battery_v", battery);
  }
  extra.add("motor_temp", temperature);
  table = extra;
  const fs::path log = dir / "extra.csv";
  write_csv(log, table, {"auto", "manual"});
  std::string head = kMapHead;
  head.replace(head.find("column = \"time\""), 15, "column = \"time\"\nunit = \"ms\"");
  const fs::path map = write_map(dir / "extra.toml", head + kStatesSi + kControls);
  const json report = import(log, map, dir / "extra.h5");
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["ignored_columns"], json({"battery_v", "motor_temp", "mode"}));
  EXPECT_EQ(report["rows"]["dropped"], 0);
  EXPECT_NEAR(report["dt"].get<double>(), kLogDt, 1e-12);
  // The text report says the same.
  const auto text = test::run_cli("data import " + quote(log) + " --system cartpole --map " + quote(map) + " --out " +
                                  quote(dir / "extra.csv.out.csv"));
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("ignored columns: battery_v, motor_temp, mode"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("840 read, 840 used, 0 dropped; 840 samples written"), std::string::npos) << text.out;
  EXPECT_EQ(read_measurements(dir / "extra.csv.out.csv", system_signature("cartpole")).sample_count(), 840);
  expect_same_diagnosis(dir / "extra.h5", "extra columns");
}

TEST_F(DataImportDefectsCli, DegreesAndMillimetresInAMatFile) {
  const double deg = 180.0 / std::numbers::pi;
  const LogTable table = table_of(clean_logs, 1.0, 1000.0, deg, true, kAll);
  // time, trial, cart and force as vectors; the pole's angle and rate as fields of a struct "pole".
  test::MatVectors vectors, pole;
  for (std::size_t c = 0; c < table.names.size(); ++c) {
    if (table.names[c].starts_with("pole_")) pole.emplace_back(table.names[c], table.columns[c]);
    else vectors.emplace_back(table.names[c], table.columns[c]);
  }
  const fs::path log = dir / "degrees.mat";
  test::write_mat_file(log, vectors, "pole", pole);
  const fs::path map = write_map(dir / "degrees.toml",
                                 kMapHead +
                                     "[states]\nx = { column = \"cart_pos\", unit = \"mm\" }\n"
                                     "x_dot = { column = \"cart_vel\", unit = \"mm/s\" }\n"
                                     "theta = { column = \"pole.pole_angle\", unit = \"deg\" }\n"
                                     "theta_dot = { column = \"pole.pole_rate\", unit = \"deg/s\" }\n\n" +
                                     kControls);
  const json report = import(log, map, dir / "degrees.h5");
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["format"], "mat");
  const MeasurementSet set = read_measurements(dir / "degrees.h5", system_signature("cartpole"));
  ASSERT_EQ(set.episodes.size(), static_cast<std::size_t>(kEpisodes));
  EXPECT_NEAR(set.episodes[2].x(17, 2), clean_logs[2].x(17, 2), 1e-12);  // back in radians
  EXPECT_NEAR(set.episodes[2].x(17, 0), clean_logs[2].x(17, 0), 1e-12);  // back in metres
  expect_same_diagnosis(dir / "degrees.h5", "degrees");
}

// The velocity has a corner at every control switch (the acceleration jumps), and a polynomial fit
// across a corner smooths the jump: with window 7 / order 2 the diagnosis of this data reads the
// smoothed steps as a weaker actuator (actuator_gain ~0.6 on every seed tried), window 5 / order 2
// passes on most seeds; window 9 / order 4, the map's defaults, follows the corners closely enough on
// all seeds tried.
TEST_F(DataImportDefectsCli, PositionsOnlyGetEstimatedVelocities) {
  const fs::path log = dir / "positions.csv";
  write_csv(log, table_of(clean_logs, 1.0, 1.0, 1.0, false, kAll));
  const fs::path map = write_map(dir / "positions.toml",
                                 kMapHead + "[states]\nx = { column = \"cart_pos\" }\ntheta = { column = \"pole_angle\" }\n\n" +
                                     kControls + "\n[velocities]\nmethod = \"savitzky_golay\"\n");  // the defaults
  const json report = import(log, map, dir / "positions.h5");
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["velocities"]["estimated"], json({{"x_dot", "x"}, {"theta_dot", "theta"}}));
  EXPECT_EQ(report["velocities"]["lag_s"], 0.0);
  EXPECT_NEAR(report["velocities"]["noise_gain"].get<double>(), SavitzkyGolayDerivative(9, 4).noise_gain(kLogDt), 1e-9);
  std::cout << "[ estimator ] noise gain " << report["velocities"]["noise_gain"] << " /s\n";
  expect_same_diagnosis(dir / "positions.h5", "positions only");
}

// Bad maps and logs: exit 2, "error:", the file and the line and field or column.

struct BadInputCli : ::testing::Test {
  fs::path dir = test::temporary_dir("data_import_bad");
  fs::path log = dir / "log.csv";
  void SetUp() override {
    std::ofstream(log) << "time,trial,x,xd,th,thd,f\n"
                          "0.00,0,0,0,0,0,1\n0.02,0,0,0,0,0,1\n0.04,0,0,0,0,0,1\n0.06,0,0,0,0,0,1\n";
  }
  test::CommandResult run(const std::string& map_text, const fs::path& log_file) {
    const fs::path map = write_map(dir / "map.toml", map_text);
    return test::run_cli("data import " + quote(log_file) + " --system cartpole --map " + quote(map) + " --out " +
                         quote(dir / "out.h5"));
  }
  static std::string map_text(const std::string& x_entry) {
    return "[time]\ncolumn = \"time\"\n\n[states]\n" + x_entry +
           "\nx_dot = \"xd\"\ntheta = \"th\"\ntheta_dot = \"thd\"\n\n[controls]\nforce = \"f\"\n";
  }
  void expect_error(const test::CommandResult& r, const std::vector<std::string>& parts) {
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error:", 0), 0u) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    for (const auto& part : parts) EXPECT_NE(r.err.find(part), std::string::npos) << "missing '" << part << "' in " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.h5"));
  }
};

TEST_F(BadInputCli, UnknownColumnNamesTheMapLineAndTheLogsColumns) {
  expect_error(run(map_text("x = { column = \"cart\" }"), log),
               {"map.toml:line 5: field 'states.x.column': column 'cart' is not in", "log.csv", "'time', 'trial', 'x'"});
}

TEST_F(BadInputCli, DuplicateTargetNamesTheLine) {
  expect_error(run(map_text("x = \"x\"\nx = \"xd\""), log), {"map.toml:line 6", "'x'"});
  // The same target under [states] and [controls] is caught too: force is not a state.
  expect_error(run(map_text("x = \"x\"\nforce = \"f\""), log),
               {"map.toml:line 6: field 'states.force': 'force' is not a state of cartpole", "x, x_dot, theta, theta_dot"});
}

TEST_F(BadInputCli, TimeGoingBackwardsNamesTheLogLine) {
  std::ofstream(log) << "time,trial,x,xd,th,thd,f\n0.00,0,0,0,0,0,1\n0.02,0,0,0,0,0,1\n0.04,0,0,0,0,0,1\n"
                        "0.00,1,0,0,0,0,1\n0.02,1,0,0,0,0,1\n";
  expect_error(run(map_text("x = \"x\""), log),
               {"log.csv:line 5, column 'time': time 0 s is before the previous sample's 0.04 s (line 4, column 'time')",
                "[episode] column"});
  // With the episode column the same log is fine.
  const auto ok = run("[episode]\ncolumn = \"trial\"\n" + map_text("x = \"x\""), log);
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST_F(BadInputCli, TooFewSamples) {
  std::ofstream(log) << "time,trial,x,xd,th,thd,f\n0.00,0,0,0,0,0,1\n";
  expect_error(run(map_text("x = \"x\""), log), {"log.csv:column 'time': 1 sample; expected at least 2 samples"});
  // Enough rows, but every piece is shorter than the velocity estimator's window.
  std::ofstream(log) << "time,x,th,f\n0.00,0,0,1\n0.02,0,0,1\n0.04,0,0,1\n";
  expect_error(run("[time]\ncolumn = \"time\"\n[states]\nx = \"x\"\ntheta = \"th\"\n[controls]\nforce = \"f\"\n"
                   "[velocities]\nmethod = \"savitzky_golay\"\nwindow = 7\n",
                   log),
               {"log.csv:column 'time': no piece of the log is long enough: all 3 rows dropped", "at least 7 samples"});
}

TEST_F(BadInputCli, UnknownUnitNamesTheFieldAndTheTable) {
  expect_error(run(map_text("x = { column = \"x\", unit = \"furlong\" }"), log),
               {"map.toml:line 5: field 'states.x.unit': unknown unit 'furlong'; expected one of: s, ms", "deg/s"});
  expect_error(run("[time]\ncolumn = \"time\"\nunit = \"mm\"\n" + map_text("x = \"x\"").substr(24), log),
               {"map.toml:line 3: field 'time.unit': 'mm' is not a unit of time"});
}

TEST_F(BadInputCli, BadLogsAndOtherMapMistakes) {
  expect_error(run(map_text("x = \"x\""), dir / "missing.csv"), {"missing.csv: no such file"});
  std::ofstream(dir / "log.txt") << "time\n0\n";
  expect_error(run(map_text("x = \"x\""), dir / "log.txt"), {"log.txt: unknown extension '.txt'"});
  expect_error(run(map_text("x = \"x\"") + "[velocity]\nwindow = 5\n", log),
               {"map.toml:line 12: unknown field 'velocity'; expected one of: time, episode"});
  expect_error(run(map_text("x = \"x\"") + "[resample]\ncontrols = \"linear\"\n", log),
               {"map.toml:line 13: field 'resample.controls': unknown rule 'linear'; expected \"hold\" or \"average\""});
  // Without [controls] (the map of a passive system), each control of the cart-pole is missing.
  expect_error(run("[time]\ncolumn = \"time\"\n[states]\nx = \"x\"\nx_dot = \"xd\"\ntheta = \"th\"\ntheta_dot = \"thd\"\n", log),
               {"map.toml: field 'controls': control 'force' has no column"});
}

}  // namespace
}  // namespace gpilqg
