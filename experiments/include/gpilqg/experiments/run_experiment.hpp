#pragma once
/// @file run_experiment.hpp
/// `gpilqg run`: every task of the config, for every seed, with all algorithms on equal terms
/// (algorithm_runs.hpp). Tasks run in order; a task with `transfer = true` starts each data-driven
/// algorithm from the data it collected on the previous task (the paper's second tasks).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gpilqg/experiments/algorithm_runs.hpp"
#include "gpilqg/experiments/model_slice.hpp"
#include "gpilqg/experiments/run_config.hpp"

namespace gpilqg {

struct RunOptions {
  std::vector<std::uint64_t> seeds = {1};
  /// GP backends to compare: empty runs "gp_ilqg" with [gp].backend; a list runs "gp_ilqg_<backend>"
  /// for each and "gp_ilqg" is the first of them.
  std::vector<std::string> backends;
  std::function<void(const std::string&)> progress;  ///< one line per finished iteration (may be empty)
  /// Keeps every completed iteration and restores what an interrupted run had (run_checkpoint.hpp);
  /// null: nothing is kept. Not owned.
  RunJournal* journal = nullptr;
  /// Threads inside one unit of work (GP outputs fitted concurrently, PDDP's belief step); the
  /// results do not depend on it. Under MPI each rank uses its share of the node's cores.
  int threads = 2;
};

struct TaskResults {
  std::vector<std::string> algorithms;            ///< names, in order
  std::vector<std::vector<AlgorithmRun>> seeds;   ///< [seed][algorithm]
  ModelSlice slice;                               ///< from the first seed's gp_ilqg (when it has data)
};

struct RunResults {
  RunConfig config;
  RunOptions options;
  std::vector<TaskResults> tasks;  ///< in config.tasks order
};

RunResults run_experiment(const RunConfig& config, const RunOptions& options);

}  // namespace gpilqg
