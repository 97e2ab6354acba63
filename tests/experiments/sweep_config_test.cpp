/// The sweep file of `gpilqg sweep` (sweep_config.hpp): the grid's points, their order and labels,
/// each point's config equal to the run config with those fields set, and errors that name the file,
/// the field and the point.

#include "gpilqg/experiments/sweep_config.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "gpilqg/experiments/cli_errors.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

/// A sweep file (with the tiny run config beside it as base.toml).
fs::path sweep_file(const std::string& name, const std::string& text) {
  const fs::path dir = test::temporary_dir("sweep_config");
  std::ofstream(dir / "base.toml") << test::kTinyRun;
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string error_of(const fs::path& file) {
  try {
    load_sweep_config(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SweepConfig, TheGridIsTheProductInFileOrderWithTheLastFieldFastest) {
  const auto file = sweep_file("grid.toml", R"(system = "cartpole"
config = "base.toml"
seeds = 3
first_seed = 5
[grid]
"loop.rollouts" = [1, 2, 3]
"gp.backend" = ["exact", "fitc"]
)");
  const SweepConfig s = load_sweep_config(file);
  EXPECT_EQ(s.seeds, (std::vector<std::uint64_t>{5, 6, 7}));
  EXPECT_EQ(s.fields, (std::vector<std::string>{"loop.rollouts", "gp.backend"})) << "file order, not sorted";
  EXPECT_EQ(s.out, file.parent_path() / "grid.h5");
  ASSERT_EQ(s.points.size(), 6u);
  EXPECT_EQ(s.points[0].label(), "loop.rollouts = 1, gp.backend = 'exact'");
  EXPECT_EQ(s.points[1].label(), "loop.rollouts = 1, gp.backend = 'fitc'");
  EXPECT_EQ(s.points[5].label(), "loop.rollouts = 3, gp.backend = 'fitc'");
  for (std::size_t p = 0; p < 6; ++p) {
    EXPECT_EQ(s.points[p].config.rollouts, static_cast<int>(p / 2) + 1);
    EXPECT_EQ(s.points[p].config.gp.backend, p % 2 == 0 ? "exact" : "fitc");
  }
  // Every other field is the base config's: the point's config is the base run config with two fields set.
  const RunConfig base = parse_run_config("cartpole", test::kTinyRun, "base.toml");
  EXPECT_EQ(s.points[0].config.iterations, base.iterations);
  EXPECT_EQ(s.points[0].config.tasks.size(), base.tasks.size());
  EXPECT_EQ(s.points[0].config.gp.backend_settings.exact_points, base.gp.backend_settings.exact_points);
}

TEST(SweepConfig, ArrayValuedFieldsAndFieldsOfATaskCanVary) {
  const auto file = sweep_file("arrays.toml", R"(system = "cartpole"
config = "base.toml"
iterations = 1
[grid]
"noise.actuator_multiplicative" = [[0.02], [0.1]]
"tasks[1].horizon" = [12]
)");
  const SweepConfig s = load_sweep_config(file);
  ASSERT_EQ(s.points.size(), 2u);
  EXPECT_DOUBLE_EQ(s.points[1].config.noise.multiplicative_std(0), 0.1);
  EXPECT_EQ(s.points[1].config.tasks[1].horizon, 12);
  EXPECT_EQ(s.points[1].config.tasks[0].horizon, 15) << "only the second task changes";
  EXPECT_EQ(s.points[0].config.iterations, 1);
}

TEST(SweepConfig, ErrorsNameTheFileTheFieldAndThePoint) {
  EXPECT_NE(error_of(sweep_file("typo.toml", "system = \"cartpole\"\n[grid]\n\"gp.bakend\" = [\"exact\"]\n")).find("gp.bakend"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("typo.toml", "system = \"cartpole\"\n[grid]\n\"gp.bakend\" = [\"exact\"]\n")).find("typo.toml:line 3"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("empty.toml", "system = \"cartpole\"\n[grid]\n\"loop.rollouts\" = []\n")).find("non-empty array"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("scalar.toml", "system = \"cartpole\"\n[grid]\n\"loop.rollouts\" = 2\n")).find("non-empty array"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("nogrid.toml", "system = \"cartpole\"\n")).find("grid"), std::string::npos);
  EXPECT_NE(error_of(sweep_file("key.toml", "system = \"cartpole\"\nseed = 3\n[grid]\n\"loop.rollouts\" = [1]\n")).find("seed"),
            std::string::npos);
  const std::string wrong = error_of(sweep_file("wrong.toml", "system = \"cartpole\"\n[grid]\n\"loop.rollouts\" = [1, \"x\"]\n"));
  EXPECT_NE(wrong.find("wrong.toml: grid point 1 (loop.rollouts = 'x')"), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("loop.rollouts"), std::string::npos) << wrong;
  for (const char* path : {"tasks[1][0].horizon", "tasks[-1].horizon", "tasks[1x].horizon", "tasks[1]horizon", "tasks[].x0"})
    EXPECT_NE(error_of(sweep_file("index.toml", std::string("system = \"cartpole\"\n[grid]\n\"") + path + "\" = [3]\n"))
                  .find("is not a field of the run config"),
              std::string::npos)
        << path;
  EXPECT_NE(error_of(sweep_file("both.toml", "system = \"cartpole\"\niterations = 2\n[grid]\n\"loop.iterations\" = [1, 3]\n"))
                .find("would override every value"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("table.toml", "system = \"cartpole\"\n[grid]\n\"gp\" = [{backend = \"fitc\"}]\n")).find("is a table"),
            std::string::npos);
  EXPECT_NE(error_of(sweep_file("nosys.toml", "system = \"nosuch\"\n[grid]\n\"loop.rollouts\" = [1]\n")).find("nosuch"),
            std::string::npos);
}

}  // namespace
}  // namespace gpilqg
