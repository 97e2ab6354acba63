/// `gpilqg data info` formatting: the terminal table and the JSON document
/// (docs/command-line.md#gpilqg-data-info-file---system-name---json).

#include "gpilqg/experiments/data_info.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace gpilqg {
namespace {

MeasurementSummary example_summary() {
  MeasurementSummary s;
  s.system = "cartpole";
  s.episodes = 2;
  s.samples = 5;
  s.dt_min = 0.05;
  s.dt_max = 0.05;
  s.duration = 0.15;
  s.states = {{"x", "m", -1.0, 6.0, 3.2, 1.5},
              {"x_dot", "m/s", 0.0, 0.0, 0.0, 0.0},
              {"theta", "rad", -1.0, -1.0, -1.0, 0.0},
              {"theta_dot", "rad/s", 0.5, 2.5, 1.25, 0.75}};
  s.controls = {{"force", "N", -11.2, 10.0, -0.2, 0.5}};
  return s;
}

TEST(DataInfo, CommonDtWithinTheContractTolerance) {
  MeasurementSummary s = example_summary();
  ASSERT_TRUE(common_dt(s).has_value());
  EXPECT_EQ(*common_dt(s), 0.05);
  s.dt_max = 0.05 * (1 + 1e-9);  // steps written with few digits still agree
  EXPECT_TRUE(common_dt(s).has_value());
  s.dt_max = 0.1;
  EXPECT_FALSE(common_dt(s).has_value());
}

TEST(DataInfo, TableListsEveryColumnWithUnitAndStatistics) {
  const std::string table = format_data_info("runs/cart.csv", example_summary());
  for (const char* part :
       {"file      runs/cart.csv\n", "system    cartpole\n", "episodes  2\n", "samples   5\n",
        "dt        0.05 s\n", "duration  0.15 s\n", "theta_dot", "rad/s", "force", "-11.2"})
    EXPECT_NE(table.find(part), std::string::npos) << "'" << part << "' not in:\n" << table;
  // One line per column after the heading, states then controls.
  const auto x_line = table.find("\nstate    x ");
  const auto force_line = table.find("\ncontrol  force ");
  EXPECT_NE(x_line, std::string::npos) << table;
  EXPECT_NE(force_line, std::string::npos) << table;
  EXPECT_LT(x_line, force_line);
  EXPECT_EQ(table.back(), '\n');
}

TEST(DataInfo, TableShowsTheRangeWhenEpisodesDisagreeOnDt) {
  MeasurementSummary s = example_summary();
  s.dt_max = 0.1;
  EXPECT_NE(format_data_info("a.csv", s).find("dt        0.05 to 0.1 s (differs between episodes)"),
            std::string::npos);
}

TEST(DataInfo, JsonHasTheFixedKeys) {
  const nlohmann::json j = data_info_json("runs/cart.csv", example_summary());
  EXPECT_EQ(j.at("file"), "runs/cart.csv");
  EXPECT_EQ(j.at("system"), "cartpole");
  EXPECT_EQ(j.at("episodes"), 2);
  EXPECT_EQ(j.at("samples"), 5);
  EXPECT_EQ(j.at("dt"), 0.05);
  EXPECT_EQ(j.at("dt_min"), 0.05);
  EXPECT_EQ(j.at("dt_max"), 0.05);
  EXPECT_EQ(j.at("duration_s"), 0.15);
  ASSERT_EQ(j.at("states").size(), 4u);
  ASSERT_EQ(j.at("controls").size(), 1u);
  const nlohmann::json& x = j.at("states").at(0);
  EXPECT_EQ(x.at("name"), "x");
  EXPECT_EQ(x.at("unit"), "m");
  EXPECT_EQ(x.at("min"), -1.0);
  EXPECT_EQ(x.at("max"), 6.0);
  EXPECT_EQ(x.at("mean"), 3.2);
  EXPECT_EQ(x.at("std"), 1.5);
  EXPECT_EQ(j.at("states").at(3).at("name"), "theta_dot");
  EXPECT_EQ(j.at("controls").at(0).at("name"), "force");
  EXPECT_EQ(j.at("controls").at(0).at("min"), -11.2);
  // Doubles survive the text form exactly.
  EXPECT_EQ(nlohmann::json::parse(j.dump()), j);
}

TEST(DataInfo, JsonDtIsNullWhenEpisodesDisagree) {
  MeasurementSummary s = example_summary();
  s.dt_max = 0.1;
  const nlohmann::json j = data_info_json("a.csv", s);
  ASSERT_TRUE(j.contains("dt"));
  EXPECT_TRUE(j.at("dt").is_null());
  EXPECT_EQ(j.at("dt_max"), 0.1);
}

}  // namespace
}  // namespace gpilqg
