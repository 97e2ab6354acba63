// Patterns in the map of `gpilqg data import` (docs/data-import.md#patterns): a 7-joint arm written as
// MJCF by the test, whose 21 states and controls three pattern lines map, with an explicit line
// winning over a pattern; the imported values against the logged ones converted by hand; `data info`
// naming the motors' unit; and the pattern mistakes, each naming the map's line and field.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <fmt/format.h>
#include <numbers>

#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/systems.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace import_patterns {  // named: the unity build puts several test files in one unit
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::quote;

constexpr int kJoints = 7;
constexpr int kRows = 20;
constexpr double kDt = 0.02;
constexpr double kDeg = std::numbers::pi / 180.0;

/// A chain of 7 hinges q1..q7, each driven by a motor tau1..tau7 (tau3 through a gear of 50).
fs::path write_arm(const fs::path& dir) {
  std::string bodies, close, motors;
  for (int i = 1; i <= kJoints; ++i) {
    bodies += fmt::format(R"(<body pos="0 0 -0.1"><joint name="q{}" type="hinge" axis="0 1 0"/>)"
                          R"(<geom type="capsule" fromto="0 0 0 0 0 -0.1" size="0.02" mass="0.5"/>)", i);
    close += "</body>";
    motors += fmt::format(R"(<motor name="tau{}" joint="q{}" gear="{}"/>)", i, i, i == 3 ? 50 : 1);
  }
  return test::write_text(dir / "arm7.xml",
                          R"(<mujoco model="arm7"><option timestep="0.01"/><default><geom contype="0" conaffinity="0"/></default>)"
                          "<worldbody>" + bodies + close + "</worldbody><actuator>" + motors + "</actuator></mujoco>\n");
}

double position(int joint, int row) { return 0.1 * joint + 0.01 * row; }       // pos<i> [rad]
double rate_deg(int joint, int row) { return 10.0 * joint + row; }             // dq<i> [deg/s]
double effort(int joint, int row) { return joint + 0.5 * (row % 2); }          // effort<i> [N m]
double elbow_deg(int row) { return 30.0 + row; }                                // elbow_deg [deg]

/// The robot's log: time, pos1..pos7, dq1..dq7 (deg/s), effort1..effort7, and q3 again in degrees
/// (`elbow_deg`); `skip` leaves one column out.
fs::path write_log(const fs::path& dir, const std::string& skip = "") {
  std::vector<std::string> names{"time"};
  for (const char* prefix : {"pos", "dq", "effort"})
    for (int i = 1; i <= kJoints; ++i) names.push_back(prefix + std::to_string(i));
  names.push_back("elbow_deg");
  std::string text;
  for (const std::string& name : names)
    if (name != skip) text += (text.empty() ? "" : ",") + name;
  text += '\n';
  for (int k = 0; k < kRows; ++k) {
    std::string row;
    for (const std::string& name : names) {
      if (name == skip) continue;
      double value = k * kDt;
      if (name == "elbow_deg") value = elbow_deg(k);
      else if (name.starts_with("pos")) value = position(std::stoi(name.substr(3)), k);
      else if (name.starts_with("dq")) value = rate_deg(std::stoi(name.substr(2)), k);
      else if (name.starts_with("effort")) value = effort(std::stoi(name.substr(6)), k);
      row += (row.empty() ? "" : ",") + fmt::format("{}", value);
    }
    text += row + '\n';
  }
  return test::write_text(dir / "arm_log.csv", text);
}

const std::string kMap = R"([time]
column = "time"

[states]
"q{i}" = "pos{i}"
"q{i}_dot" = { column = "dq{i}", unit = "deg/s" }
q3 = { column = "elbow_deg", unit = "deg" }

[controls]
"tau{i}" = "effort{i}"
)";

struct MapPatternCli : ::testing::Test {
  fs::path dir = test::temporary_dir("import_patterns");
  fs::path arm = write_arm(dir);
  test::CommandResult import(const std::string& map, const fs::path& log, const fs::path& out) {
    const fs::path map_file = test::write_text(dir / "map.toml", map);
    return test::run_cli("data import " + quote(log) + " --system " + quote(arm) + " --map " + quote(map_file) +
                         " --out " + quote(out));
  }
  void expect_error(const test::CommandResult& r, const std::vector<std::string>& parts) {
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error:", 0), 0u) << r.err;
    for (const std::string& part : parts)
      EXPECT_NE(r.err.find(part), std::string::npos) << "missing '" << part << "' in " << r.err;
  }
};

TEST_F(MapPatternCli, ThreePatternLinesMapASevenJointArmAndAnExplicitLineWins) {
  const fs::path out = dir / "arm.csv";
  const auto r = import(kMap, write_log(dir), out);
  ASSERT_EQ(r.status, 0) << r.err;
  const MeasurementSet set = read_measurements(out, system_signature(arm.string()));
  ASSERT_EQ(set.episodes.size(), 1u);
  const Episode& e = set.episodes[0];
  ASSERT_EQ(e.length(), kRows);
  for (int k = 0; k < kRows; ++k)
    for (int i = 1; i <= kJoints; ++i) {
      const double q = i == 3 ? elbow_deg(k) * kDeg : position(i, k);  // q3 from its explicit line
      EXPECT_NEAR(e.x(k, i - 1), q, 1e-12) << "q" << i << " row " << k;
      EXPECT_NEAR(e.x(k, kJoints + i - 1), rate_deg(i, k) * kDeg, 1e-12) << "q" << i << "_dot row " << k;
      EXPECT_NEAR(e.u(k, i - 1), effort(i, k), 1e-12) << "tau" << i << " row " << k;
    }
  EXPECT_NE(r.out.find("ignored columns: pos3\n"), std::string::npos) << r.out;  // q3 reads elbow_deg

  // The motors on hinges take torques, whatever their gear.
  const auto info = test::run_cli("data info " + quote(out) + " --system " + quote(arm) + " --json");
  ASSERT_EQ(info.status, 0) << info.err;
  const json j = json::parse(info.out);
  for (int i = 0; i < kJoints; ++i) {
    EXPECT_EQ(j["states"][i]["unit"], "rad");
    EXPECT_EQ(j["states"][kJoints + i]["unit"], "rad/s");
    EXPECT_EQ(j["controls"][i]["unit"], "N m") << j["controls"][i]["name"];
  }
  const auto table = test::run_cli("data info " + quote(out) + " --system " + quote(arm));
  EXPECT_NE(table.out.find("control  tau3    N m"), std::string::npos) << table.out;
}

TEST_F(MapPatternCli, APatternMatchingNothingNamesTheLineAndTheSystemsNames) {
  std::string map = kMap;
  map.replace(map.find("\"tau{i}\""), 8, "\"motor{i}\"");
  expect_error(import(map, write_log(dir), dir / "out.h5"),
               {"map.toml:line 10: field 'controls.\"motor{i}\"': the pattern 'motor{i}' matches no control of arm7",
                "expected a pattern whose {i} (a whole number) makes it one of the controls: tau1, tau2"});
}

TEST_F(MapPatternCli, APatternToAMissingColumnNamesTheLineTheNameAndTheLogsColumns) {
  expect_error(import(kMap, write_log(dir, "dq6"), dir / "out.h5"),
               {"map.toml:line 6: field 'states.\"q{i}_dot\"': column 'dq6' (the pattern 'q{i}_dot' = 'dq{i}' for 'q6_dot') "
                "is not in",
                "arm_log.csv", "expected one of its columns: 'time', 'pos1'"});
}

TEST_F(MapPatternCli, AMalformedPatternNamesTheLineAndTheSyntax) {
  std::string map = kMap;
  map.replace(map.find("\"q{i}\" = \"pos{i}\""), 17, "\"q{j}\" = \"pos{j}\"");
  expect_error(import(map, write_log(dir), dir / "out.h5"),
               {"map.toml:line 5: field 'states.\"q{j}\"': the pattern 'q{j}' must hold the placeholder {i} exactly once",
                "expected a pattern such as \"q{i}\" = \"pos{i}\""});
  map = kMap;
  map.replace(map.find("\"effort{i}\""), 11, "\"effort\"");
  expect_error(import(map, write_log(dir), dir / "out.h5"),
               {"map.toml:line 10: field 'controls.\"tau{i}\"': the column 'effort' has no placeholder"});
}

}  // namespace
}  // namespace import_patterns
}  // namespace gpilqg
