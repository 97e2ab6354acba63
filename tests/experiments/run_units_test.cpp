/// The units of `gpilqg run` (run_units.hpp) and their scheduler (unit_scheduler.hpp): the
/// dependencies a distributed run must respect, the scheduler's order, and the decisive property that
/// running the units in any order the dependencies allow gives exactly the single-process result.

#include "gpilqg/experiments/run_units.hpp"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "gpilqg/experiments/unit_scheduler.hpp"
#include "same_run_results.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

int find_unit(const std::vector<RunUnit>& units, std::uint64_t seed, int task, const std::string& algorithm) {
  for (std::size_t i = 0; i < units.size(); ++i)
    if (units[i].seed == seed && units[i].task == task && units[i].algorithm == algorithm) return static_cast<int>(i);
  return -1;
}

TEST(RunUnits, EveryAlgorithmTaskAndSeedIsOneUnitWithTheDependenciesOfThePaperProtocol) {
  const RunConfig config = test::tiny_run_config();  // two tasks, the second a transfer task; pddp and pddp_own on
  RunOptions options;
  options.seeds = {7, 8};
  const auto units = plan_run_units(config, options);
  ASSERT_EQ(units.size(), 2u * 2u * 5u);
  for (const std::uint64_t seed : {7u, 8u}) {
    const int gp0 = find_unit(units, seed, 0, "gp_ilqg"), gp1 = find_unit(units, seed, 1, "gp_ilqg");
    const int own0 = find_unit(units, seed, 0, "pddp_own"), own1 = find_unit(units, seed, 1, "pddp_own");
    ASSERT_GE(gp0, 0);
    ASSERT_GE(own1, 0);
    EXPECT_TRUE(units[static_cast<std::size_t>(gp0)].depends_on.empty());
    EXPECT_EQ(units[static_cast<std::size_t>(gp1)].depends_on, std::vector<int>{gp0}) << "transfer task";
    EXPECT_EQ(units[static_cast<std::size_t>(own1)].depends_on, std::vector<int>{own0}) << "transfer task";
    for (int t = 0; t < 2; ++t) {
      EXPECT_EQ(units[static_cast<std::size_t>(find_unit(units, seed, t, "pddp"))].depends_on,
                std::vector<int>{find_unit(units, seed, t, "gp_ilqg")})
          << "pddp learns from gp_ilqg's data";
      EXPECT_TRUE(units[static_cast<std::size_t>(find_unit(units, seed, t, "ilqg_real"))].depends_on.empty());
    }
  }
  for (std::size_t i = 0; i < units.size(); ++i)
    for (const int d : units[i].depends_on) EXPECT_LT(d, static_cast<int>(i)) << "a dependency comes first";
  EXPECT_EQ(describe_unit(units[2], config), "seed 7, task first, gp_ilqg");
}

TEST(RunUnits, ComparedBackendsAreSeparateUnitsAndPddpLearnsFromTheFirst) {
  RunOptions options;
  options.seeds = {1};
  options.backends = {"fitc", "exact"};
  const auto units = plan_run_units(test::tiny_run_config(), options);
  const int first = find_unit(units, 1, 0, "gp_ilqg_fitc");
  ASSERT_GE(first, 0);
  ASSERT_GE(find_unit(units, 1, 0, "gp_ilqg_exact"), 0);
  EXPECT_EQ(units[static_cast<std::size_t>(find_unit(units, 1, 0, "pddp"))].depends_on, std::vector<int>{first});
  EXPECT_EQ(units[static_cast<std::size_t>(find_unit(units, 1, 1, "gp_ilqg_exact"))].depends_on,
            std::vector<int>{find_unit(units, 1, 0, "gp_ilqg_exact")});
}

TEST(UnitScheduler, StartsTheLongestChainFirstAndOnlyReadyUnits) {
  // 0 -> 1 -> 2 (a chain of 3 x 10) and two independent units of weight 1 and 15.
  UnitScheduler s({{}, {0}, {1}, {}, {}}, {10, 10, 10, 1, 15});
  EXPECT_DOUBLE_EQ(s.priority(0), 30);
  EXPECT_DOUBLE_EQ(s.priority(2), 10);
  EXPECT_EQ(s.next(), 0);  // 30 before 15 before 1
  EXPECT_EQ(s.next(), 4);
  EXPECT_EQ(s.next(), 3);
  EXPECT_EQ(s.next(), std::nullopt) << "1 waits for 0";
  s.finished(0);
  EXPECT_EQ(s.next(), 1);
  s.requeue(1);  // its worker stopped
  EXPECT_EQ(s.running_count(), 2);
  EXPECT_EQ(s.next(), 1);
  for (const int i : {1, 3, 4}) s.finished(i);
  EXPECT_EQ(s.next(), 2);
  EXPECT_FALSE(s.all_finished());
  s.finished(2);
  EXPECT_TRUE(s.all_finished());
  EXPECT_EQ(s.next(), std::nullopt);
  EXPECT_THROW(s.finished(2), std::logic_error);
}

TEST(UnitScheduler, RefusesDependenciesThatDoNotComeFirstAndWeightsThatAreNotPositive) {
  EXPECT_THROW(UnitScheduler({{1}, {}}, {1, 1}), std::invalid_argument);
  EXPECT_THROW(UnitScheduler({{0}}, {1}), std::invalid_argument);
  EXPECT_THROW(UnitScheduler({{}, {}}, {1, 0}), std::invalid_argument);
  EXPECT_THROW(UnitScheduler({{}}, {1, 1}), std::invalid_argument);
}

/// Three workers take units in the scheduler's order and finish them in a shuffled order: every
/// interleaving a distributed run can produce. The assembled result equals the single-process run's.
TEST(RunUnits, AnyOrderTheDependenciesAllowGivesTheSingleProcessResult) {
  const RunConfig config = test::tiny_run_config();
  RunOptions options;
  options.seeds = {3, 4};
  const RunResults reference = run_experiment(config, options);

  const RunModels models = make_run_models(config);
  const auto units = plan_run_units(config, options);
  std::vector<std::vector<int>> depends_on;
  std::vector<double> weights;
  for (const auto& u : units) depends_on.push_back(u.depends_on), weights.push_back(u.weight);
  UnitScheduler scheduler(depends_on, weights);
  std::vector<std::optional<AlgorithmRun>> runs(units.size());
  const CompletedRun completed = [&](int i) { return runs.at(static_cast<std::size_t>(i)).value(); };
  std::mt19937 rng(11);
  std::vector<int> order;
  while (!scheduler.all_finished()) {
    std::vector<int> started;
    while (started.size() < 3)
      if (auto u = scheduler.next()) started.push_back(*u);
      else break;
    ASSERT_FALSE(started.empty()) << "nothing ready although units are left";
    std::shuffle(started.begin(), started.end(), rng);
    for (const int u : started) {
      runs[static_cast<std::size_t>(u)] = run_unit(config, options, models, units, u, completed);
      scheduler.finished(u);
      order.push_back(u);
    }
  }
  EXPECT_FALSE(std::is_sorted(order.begin(), order.end())) << "the test must run the units out of list order";
  std::vector<AlgorithmRun> finished;
  for (auto& r : runs) finished.push_back(std::move(*r));
  test::expect_same_results(assemble_run_results(config, options, models, units, std::move(finished)), reference);
}

}  // namespace
}  // namespace gpilqg
