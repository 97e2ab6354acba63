// Patterns of an import map (map_patterns.hpp): which names a pattern matches, the column it gives
// each, its syntax, and the expansion over a system's names with explicit entries winning. The
// expected columns are written out by hand from the rules of docs/data-import.md#patterns.

#include "gpilqg/core/map_patterns.hpp"

#include <gtest/gtest.h>

#include "gpilqg/core/measurements.hpp"

namespace gpilqg {
namespace {

ColumnMapping pattern(const std::string& target, const std::string& column, long line = 3) {
  return {target, column, "", 1.0, {"map.toml", line, "states.\"" + target + "\""}, ""};
}

TEST(MapPatterns, ThePlaceholderIsAWholeNumberAndTheRestIsLiteral) {
  const ColumnMapping q = pattern("q{i}", "pos{i}");
  EXPECT_EQ(pattern_column(q, "q1"), "pos1");
  EXPECT_EQ(pattern_column(q, "q12"), "pos12");
  EXPECT_EQ(pattern_column(q, "q07"), "pos07");  // the digits as written
  EXPECT_EQ(pattern_column(q, "q1_dot"), std::nullopt);
  EXPECT_EQ(pattern_column(q, "q"), std::nullopt);
  EXPECT_EQ(pattern_column(q, "qa"), std::nullopt);
  EXPECT_EQ(pattern_column(q, "xq1"), std::nullopt);
  const ColumnMapping qd = pattern("joint{i}_dot", "j{i}/vel");
  EXPECT_EQ(pattern_column(qd, "joint3_dot"), "j3/vel");
  EXPECT_EQ(pattern_column(qd, "joint3"), std::nullopt);
}

TEST(MapPatterns, AnOffsetShiftsTheNumber) {
  EXPECT_EQ(pattern_column(pattern("panda_joint{i}", "position_{i-1}"), "panda_joint1"), "position_0");
  EXPECT_EQ(pattern_column(pattern("panda_joint{i}", "position_{i-1}"), "panda_joint07"), "position_6");
  EXPECT_EQ(pattern_column(pattern("m{i}", "u{i+10}_{i}"), "m2"), "u12_2");
  try {
    pattern_column(pattern("q{i}", "pos{i-1}", 7), "q0");
    ADD_FAILURE() << "a negative column number was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("map.toml:line 7: field 'states.\"q{i}\"': for 'q0' the column 'pos{i-1}' gives the number -1"),
              std::string::npos)
        << e.what();
  }
}

TEST(MapPatterns, SyntaxProblemsAreNamed) {
  EXPECT_EQ(pattern_syntax_problem("q{i}", "pos{i}"), std::nullopt);
  EXPECT_EQ(pattern_syntax_problem("q{i}", "pos{i+2}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{j}", "pos{i}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{i}{i}", "pos{i}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{i", "pos{i}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{i}", "pos"), std::nullopt);       // every name would read one column
  EXPECT_NE(pattern_syntax_problem("q{i}", "pos{k}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{i}", "pos{i*2}"), std::nullopt);
  EXPECT_NE(pattern_syntax_problem("q{i}", "pos{i}}"), std::nullopt);
  EXPECT_TRUE(is_pattern("q{i}"));
  EXPECT_FALSE(is_pattern("q1"));
}

SystemSignature arm3() {
  return {"arm3",
          {{"q1", "rad"}, {"q2", "rad"}, {"q3", "rad"}, {"q1_dot", "rad/s"}, {"q2_dot", "rad/s"}, {"q3_dot", "rad/s"}},
          {{"tau1", "N m"}, {"tau2", "N m"}, {"tau3", "N m"}}};
}

TEST(MapPatterns, ExpansionFollowsTheSystemsOrderAndAnExplicitEntryWins) {
  LogMap map;
  map.file = "map.toml";
  map.states = {{"q2", "shoulder_angle", "deg", 0.5, {"map.toml", 9, "states.q2"}, ""}};
  map.state_patterns = {pattern("q{i}", "pos{i}", 10), pattern("q{i}_dot", "vel{i}", 11)};
  map.control_patterns = {pattern("tau{i}", "effort{i-1}", 13)};
  const LogMap out = expand_patterns(map, arm3());
  std::vector<std::pair<std::string, std::string>> states, controls;
  for (const ColumnMapping& m : out.states) states.emplace_back(m.target, m.column);
  for (const ColumnMapping& m : out.controls) controls.emplace_back(m.target, m.column);
  EXPECT_EQ(states, (std::vector<std::pair<std::string, std::string>>{
                        {"q2", "shoulder_angle"}, {"q1", "pos1"}, {"q3", "pos3"},
                        {"q1_dot", "vel1"}, {"q2_dot", "vel2"}, {"q3_dot", "vel3"}}));
  EXPECT_EQ(controls, (std::vector<std::pair<std::string, std::string>>{
                          {"tau1", "effort0"}, {"tau2", "effort1"}, {"tau3", "effort2"}}));
  EXPECT_EQ(out.states[0].scale, 0.5);        // the explicit entry, untouched
  EXPECT_EQ(out.states[1].origin.line, 10);   // an expanded entry points at its pattern's line
  EXPECT_EQ(out.states[1].pattern, "'q{i}' = 'pos{i}'");
  EXPECT_TRUE(out.state_patterns.empty());
}

std::string expansion_error(const LogMap& map) {
  try {
    expand_patterns(map, arm3());
  } catch (const DataError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MapPatterns, APatternMatchingNothingOrANameMatchedTwiceIsAnError) {
  LogMap map;
  map.state_patterns = {pattern("joint{i}", "pos{i}", 4)};
  const std::string none = expansion_error(map);
  EXPECT_NE(none.find("map.toml:line 4: field 'states.\"joint{i}\"': the pattern 'joint{i}' matches no state of arm3"),
            std::string::npos)
      << none;
  EXPECT_NE(none.find("q1, q2, q3, q1_dot"), std::string::npos) << none;

  map.state_patterns = {pattern("q{i}", "pos{i}", 4), pattern("q{i}", "angle{i}", 5)};
  const std::string twice = expansion_error(map);
  EXPECT_NE(twice.find("map.toml:line 5"), std::string::npos) << twice;
  EXPECT_NE(twice.find("state 'q1' is matched by this pattern 'q{i}' and by 'q{i}' (line 4)"), std::string::npos) << twice;
  // An explicit entry settles the name for both patterns, so only the names they still share count.
  map.states = {{"q1", "a", "", 1.0, {"map.toml", 3, "states.q1"}, ""}, {"q2", "b", "", 1.0, {"map.toml", 3, "states.q2"}, ""},
                {"q3", "c", "", 1.0, {"map.toml", 3, "states.q3"}, ""}};
  map.state_patterns.push_back(pattern("q{i}_dot", "vel{i}", 6));
  EXPECT_EQ(expansion_error(map), "no error");
}

}  // namespace
}  // namespace gpilqg
