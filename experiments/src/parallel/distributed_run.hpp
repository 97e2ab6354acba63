#pragma once
/// @file distributed_run.hpp
/// `mpirun -np K gpilqg run ...`: the run's units (run_units.hpp: one algorithm on one task for one
/// seed) spread over K ranks by unit_distribution.hpp, respecting their dependencies.
///
/// Every rank keeps each unit it runs in the run's one checkpoint folder (run_checkpoint.hpp: one
/// file per unit, replaced after every completed iteration), which must be on a file system all
/// ranks see, as a cluster's home or scratch space is. A unit's dependencies are read from there
/// once they have finished, and at the end rank 0 assembles the results from the finished units and
/// writes the result file exactly as the single-process run does. Since a unit computes the same
/// numbers on any rank (run_units.hpp), the result file equals the single-process run's in every
/// dataset except the wall-clock times. `--resume` continues from the checkpoint with any number of
/// ranks.

#include <functional>

#include "gpilqg/experiments/run_checkpoint.hpp"
#include "unit_distribution.hpp"

namespace gpilqg::cli {

struct DistributedRun {
  Distribution distribution;  ///< how it ended; on rank 0 also which rank ran each unit, and how long
  RunResults results;         ///< rank 0, when every unit finished: the run's results
  std::string failed_unit;    ///< rank 0, when a unit failed: which one ("seed 3, task swingup, gp_ilqg")
};

/// Every rank calls this with the same config and options; `checkpoint` is this rank's handle on the
/// shared checkpoint folder (options.journal must point to it).
DistributedRun run_distributed(const MpiSession& session, const RunConfig& config, const RunOptions& options,
                               RunCheckpoint& checkpoint, const std::function<bool()>& stop_signal);

}  // namespace gpilqg::cli
