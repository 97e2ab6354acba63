#pragma once
/// @file run_units.hpp
/// `gpilqg run` as a list of units of work: one algorithm on one task for one seed. The single-process
/// run executes them in list order (run_experiment.hpp); `mpirun -np K gpilqg run` hands them to K
/// ranks as their dependencies complete (distributed_run.hpp). Both assemble the same RunResults from
/// the same units, so the result does not depend on how the work was spread.
///
/// Dependencies (a unit needs the complete run of each unit it depends on):
///   - a transfer task's gp_ilqg[_<backend>] and pddp_own start from the data their own algorithm
///     collected on the previous task of the same seed;
///   - pddp is trained on exactly the data gp_ilqg (the first backend) had at each iteration, on the
///     same task and seed;
///   - ilqg_real and ilqg_sim need nothing.
/// Every random number a unit draws comes from streams fixed by (seed, task, purpose, iteration)
/// (run_setup.hpp), and the thread count does not change any result, so a unit computes the same
/// numbers on any rank.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gpilqg/experiments/run_experiment.hpp"

namespace gpilqg {

enum class UnitKind { TrueModel, Simulator, GpIlqg, PddpOnGpData, PddpOwn };

struct RunUnit {
  std::size_t seed_index = 0;  ///< position of the seed in RunOptions::seeds
  std::uint64_t seed = 0;
  int task = 0;                ///< index into RunConfig::tasks
  UnitKind kind = UnitKind::TrueModel;
  /// Its name in the result (docs/formats.md#results-file-of-gpilqg-run), e.g. "gp_ilqg_fitc".
  std::string algorithm;
  std::string backend;         ///< GpIlqg: the GP backend it fits
  std::vector<int> depends_on;  ///< indices of the units whose complete runs it needs
  /// Relative expected cost, for scheduling only (a fixed-model plan 1, a learning loop 10): ranks
  /// take the ready unit with the longest chain of expected work behind it first.
  double weight = 1.0;
};

/// The units of a run, in the order the single-process run executes them: seed by seed, task by
/// task, and within a task ilqg_real, ilqg_sim, gp_ilqg per backend, pddp, pddp_own. Every unit comes
/// after the units it depends on.
std::vector<RunUnit> plan_run_units(const RunConfig& config, const RunOptions& options);

/// "seed 3, task swingup, gp_ilqg": how messages name a unit.
std::string describe_unit(const RunUnit& unit, const RunConfig& config);

/// The finished run of unit `index` (a dependency of the unit being run).
using CompletedRun = std::function<AlgorithmRun(int index)>;

/// Runs units[index] (restoring its progress from options.journal when there is one). `completed`
/// is asked only for the units it depends on.
AlgorithmRun run_unit(const RunConfig& config, const RunOptions& options, const RunModels& models,
                      const std::vector<RunUnit>& units, int index, const CompletedRun& completed);

/// The finished run of units[index] as options.journal kept it (every iteration, the data and the
/// last model). Throws std::runtime_error naming the unit when the journal has no finished run of it.
AlgorithmRun finished_unit_from_journal(const RunConfig& config, const RunOptions& options, const RunModels& models,
                                        const std::vector<RunUnit>& units, int index);

/// The results of a run from the finished runs of all its units (runs[i] belongs to units[i]): the
/// per-task algorithm order and the Figure-1 slice of the first seed's gp_ilqg.
RunResults assemble_run_results(const RunConfig& config, const RunOptions& options, const RunModels& models,
                                const std::vector<RunUnit>& units, std::vector<AlgorithmRun> runs);

}  // namespace gpilqg
