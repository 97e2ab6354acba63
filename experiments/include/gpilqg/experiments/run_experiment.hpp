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

/// A 1-D picture of the learned model (the paper's Figure 1): one state output of the GP-corrected
/// step against one input, the other inputs held at a measured point, out to two data widths or six length-scales
/// (whichever is more) beyond the data on both sides.
struct ModelSlice {
  int output = 0, input = 0;
  Vector base;        ///< the measured point z* the slice goes through
  Vector grid;        ///< values of z_input
  Vector simulator;   ///< phi_sim(z)_output: the simulator's next state (the GP's mean function)
  Vector mean;        ///< phi_sim + mu: the corrected model
  Vector std;         ///< sqrt(var): the GP's latent standard deviation
  Vector truth;       ///< the real world's mean next state
  Vector data_z, data_y;  ///< measured transitions near the slice: z_input and x'_output
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

/// The slice through the measured point nearest the data's mean, for the output with the largest
/// signal variance and its most relevant input (shortest length-scale relative to the data's spread).
ModelSlice model_slice(const StepModel& world, const StepModel& model, const TransitionData& data);

}  // namespace gpilqg
