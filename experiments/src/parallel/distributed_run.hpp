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

/// One run of the work: `gpilqg run` has one, `gpilqg sweep` one per grid point.
struct RunPart {
  const RunConfig* config = nullptr;
  RunOptions options;                 ///< options.journal must be `checkpoint`
  RunCheckpoint* checkpoint = nullptr;  ///< this rank's handle on the part's checkpoint folder
  std::string label;                  ///< names the part in messages ("grid point 3"; empty for a run)
};

struct DistributedRuns {
  Distribution distribution;        ///< how it ended; on rank 0 also which rank ran each unit, and how long
  std::vector<RunResults> results;  ///< rank 0, when every unit finished: each part's results
  std::string failed_unit;          ///< when a unit failed: which one ("seed 3, task swingup, gp_ilqg")
};

/// Every rank calls this with the same parts. The units of all parts form one list, so the ranks
/// share the work of every part.
DistributedRuns run_distributed(const MpiSession& session, const std::vector<RunPart>& parts,
                                const std::function<bool()>& stop_signal);

}  // namespace gpilqg::cli
