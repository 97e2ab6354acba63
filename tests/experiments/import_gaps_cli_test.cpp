// `gpilqg data import` says when max_gap cuts a record of the log into several episodes: how many
// pieces each record became, every gap (its start, its length in seconds and in steps), and how to
// keep the record whole. The logs are CSV with timestamp jitter and gaps made by removing rows, so
// every gap's start and length is written out by hand from the rows removed.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "test_support.hpp"

namespace gpilqg {
namespace import_gaps {  // named: the unity build puts several test files in one unit
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::quote;

constexpr double kDt = 0.01;

/// Logged time of row k: k dt with a jitter of -1, 0 or +1 ms (k mod 3), so the steps are 11, 11 and
/// 8 ms, all well below 3 dt; only removed rows make a step longer than that.
double logged_time(int k) { return kDt * k + 0.001 * (k % 3 - 1); }

/// A cart-pole log of rows 0..rows-1 of each trial except `removed`, with an episode column.
void write_log(const fs::path& file, const std::vector<std::pair<int, std::set<int>>>& trials) {
  std::ofstream out(file);
  out.precision(17);
  out << "trial,time,x,x_dot,theta,theta_dot,force\n";
  for (std::size_t trial = 0; trial < trials.size(); ++trial)
    for (int k = 0; k < trials[trial].first; ++k)
      if (!trials[trial].second.contains(k))
        out << trial << ',' << logged_time(k) << ',' << 0.001 * k << ",0.1,0.5,0," << (k % 10) << '\n';
}

std::string map_text(const std::string& resample, bool episode_column) {
  return std::string("[time]\ncolumn = \"time\"\n") + (episode_column ? "[episode]\ncolumn = \"trial\"\n" : "") +
         "[resample]\n" + resample +
         "\n[states]\nx = \"x\"\nx_dot = \"x_dot\"\ntheta = \"theta\"\ntheta_dot = \"theta_dot\"\n"
         "[controls]\nforce = \"force\"\n";
}

std::set<int> rows_between(int first, int last) {
  std::set<int> rows;
  for (int k = first; k <= last; ++k) rows.insert(k);
  return rows;
}

struct GapReportCli : ::testing::Test {
  fs::path dir = test::temporary_dir("import_gaps");
  test::CommandResult import(const fs::path& log, const std::string& map, bool as_json) {
    const fs::path map_file = test::write_text(dir / "map.toml", map);
    return test::run_cli("data import " + quote(log) + " --system cartpole --map " + quote(map_file) + " --out " +
                         quote(dir / "out.h5") + (as_json ? " --json" : ""));
  }
};

TEST_F(GapReportCli, TheDefaultMaxGapCuttingTheRecordIsReportedWithEveryGapAndTheRemedy) {
  // One record of 400 rows without 100..102, 200..204 and 300..309.
  const fs::path log = dir / "jitter.csv";
  std::set<int> removed = rows_between(100, 102);
  removed.merge(rows_between(200, 204));
  removed.merge(rows_between(300, 309));
  write_log(log, {{400, removed}});
  const std::string map = map_text("dt = 0.01", false);  // max_gap: the default 3 dt = 0.03 s

  // The gaps run from the last row before each hole to the first after it.
  const double starts[] = {logged_time(99), logged_time(199), logged_time(299)};
  const double lengths[] = {logged_time(103) - logged_time(99), logged_time(205) - logged_time(199),
                            logged_time(310) - logged_time(299)};  // 0.041, 0.060, 0.109 s
  const auto r = import(log, map, true);
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["max_gap_source"], "3 dt");
  EXPECT_EQ(j["gaps_split"], 3);
  EXPECT_EQ(j["records"], json::parse(R"([{"source_episode": 0, "rows": 382, "pieces": 4, "episodes": 4}])"));
  ASSERT_EQ(j["gap_list"].size(), 3u);
  for (int g = 0; g < 3; ++g) {
    const json& gap = j["gap_list"][g];
    EXPECT_EQ(gap["source_episode"], 0);
    EXPECT_NEAR(gap["t_start"].get<double>(), starts[g], 1e-12);
    EXPECT_NEAR(gap["t_end"].get<double>(), starts[g] + lengths[g], 1e-12);
    EXPECT_NEAR(gap["length"].get<double>(), lengths[g], 1e-12);
    EXPECT_NEAR(gap["length_dt"].get<double>(), lengths[g] / kDt, 1e-9);
  }

  const auto text = import(log, map, false);
  ASSERT_EQ(text.status, 0) << text.err;
  for (const char* part :
       {"split: max_gap = 0.03 s (the default, 3 dt) cut the log's one record into 4 pieces at 3 gaps: 4 episodes written\n",
        "  gap at t = 0.989 s: 0.041 s = 4.1 dt\n", "  gap at t = 1.99 s: 0.06 s = 6 dt\n",
        "  gap at t = 2.991 s: 0.109 s = 10.9 dt\n",
        "to keep the record in one piece, raise max_gap in the map to the longest gap (0.109 s) or more: "
        "[resample] max_gap = 0.11 "})
    EXPECT_NE(text.out.find(part), std::string::npos) << "'" << part << "' not in:\n" << text.out;
  EXPECT_EQ(text.out.find("more (--json"), std::string::npos) << text.out;

  // The remedy works: with max_gap = 0.11 the record stays one episode.
  const auto whole = import(log, map_text("dt = 0.01\nmax_gap = 0.11", false), true);
  ASSERT_EQ(whole.status, 0) << whole.err;
  const json k = json::parse(whole.out);
  EXPECT_EQ(k["episodes"], 1);
  EXPECT_EQ(k["gap_list"], json::array());
  EXPECT_EQ(k["records"][0]["pieces"], 1);
  const auto quiet = import(log, map_text("dt = 0.01\nmax_gap = 0.11", false), false);
  EXPECT_EQ(quiet.out.find("split:"), std::string::npos) << quiet.out;
}

TEST_F(GapReportCli, TheTextListsTheFirstTenGapsAndTheJsonAllOfThemPerRecord) {
  // Trial 0: 300 rows, rows 20j + 10 .. 20j + 12 removed for j = 0 .. 12 (13 gaps of about 4 dt);
  // trial 1: 50 rows, whole.
  std::set<int> removed;
  for (int j = 0; j < 13; ++j) removed.merge(rows_between(20 * j + 10, 20 * j + 12));
  const fs::path log = dir / "hiccups.csv";
  write_log(log, {{300, removed}, {50, {}}});
  const std::string map = map_text("dt = 0.01\nmax_gap = 0.035", true);

  const auto r = import(log, map, true);
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["records"], json::parse(R"([{"source_episode": 0, "rows": 261, "pieces": 14, "episodes": 14},
                                          {"source_episode": 1, "rows": 50, "pieces": 1, "episodes": 1}])"));
  ASSERT_EQ(j["gap_list"].size(), 13u);
  EXPECT_NEAR(j["gap_list"][12]["t_start"].get<double>(), logged_time(249), 1e-12);
  EXPECT_NEAR(j["gap_list"][12]["length"].get<double>(), logged_time(253) - logged_time(249), 1e-12);

  const auto text = import(log, map, false);
  ASSERT_EQ(text.status, 0) << text.err;
  for (const char* part : {"split: max_gap = 0.035 s (from the map) cut 1 of the log's 2 records (values of 'trial'):\n",
                           "  episode 0: 14 pieces at 13 gaps: 14 episodes written\n",
                           "  gap in episode 0 at t = 0.089 s: 0.041 s = 4.1 dt\n",  // rows 9 -> 13
                           "  ... and 3 more (--json lists every gap in gap_list)\n", "to keep each record in one piece"})
    EXPECT_NE(text.out.find(part), std::string::npos) << "'" << part << "' not in:\n" << text.out;
  // The tenth gap (rows 189 -> 193) is listed, the eleventh (rows 209 -> 213) is not.
  EXPECT_NE(text.out.find("at t = 1.889 s:"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("at t = 2.091 s:"), std::string::npos) << text.out;
}

}  // namespace
}  // namespace import_gaps
}  // namespace gpilqg
