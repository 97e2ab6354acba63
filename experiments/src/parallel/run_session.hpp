#pragma once
/// @file run_session.hpp
/// What `gpilqg run` and `gpilqg sweep` share around their work under MPI: opening the checkpoints
/// on every rank, and turning how the work ended into messages and an exit status, printed once.

#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "distributed_run.hpp"

namespace gpilqg::cli {

struct CheckpointRequest {
  std::filesystem::path folder;
  const RunConfig* config = nullptr;
  const RunOptions* options = nullptr;
};

/// Runs `step` (reading options and configs) on every rank and then tells every rank whether all
/// succeeded: an error on any rank stops every rank. Rank 0 reports it once (its own error as
/// thrown; another rank's as "error: rank R on HOST: ..."), the other ranks throw ReportedElsewhere,
/// so no rank is left waiting in a collective for one that stopped. With one rank it just runs `step`.
void every_rank_then_agree(const MpiSession& mpi, const std::function<void()>& step);

/// Runs `step` on rank 0 only and then tells every rank whether it succeeded: rank 0 rethrows its
/// error, the other ranks throw ReportedElsewhere with the exit status it maps to, so no rank is left
/// waiting for one that stopped. With one rank it just runs `step`.
void on_root_then_agree(const MpiSession& mpi, const std::function<void()>& step);

/// Every requested checkpoint, created (or opened with `resume`) on every rank. Rank 0 creates or
/// checks them first; the other ranks then open them, which fails when the folders are not on a file
/// system they see. An error on any rank stops every rank before the work starts, reported once by
/// rank 0 (the others throw ReportedElsewhere).
std::vector<RunCheckpoint> open_checkpoints(const MpiSession& mpi, const std::vector<CheckpointRequest>& requests,
                                            bool resume);

/// Threads inside one unit of work: `--threads` when given (> 0), else each rank's share of its
/// machine under MPI, else RunOptions' default.
int unit_threads(const MpiSession& mpi, int option);

/// Which rank ran how many units for how long, on stderr: the numbers behind a cluster's time
/// estimate (docs/cluster.md).
void print_unit_times(const Distribution& distribution, int ranks);

/// The exit status when the work did not finish, after printing once (rank 0) why: a failed unit
/// (naming the rank and the unit, and where the finished work is) or an interruption. Nothing when
/// every unit finished.
std::optional<int> unfinished_exit_status(const MpiSession& mpi, const DistributedRuns& runs,
                                          const std::filesystem::path& checkpoint, int interrupted_status);

}  // namespace gpilqg::cli
